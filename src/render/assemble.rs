//! The output planes of a frame, filled band by band while the render
//! streams its samples: for each output pixel, the radiometry of its n×n
//! samples (eqs. 1-4, with the uniform-pixel collapse of
//! [`pixel::representatives`]) and every per-pixel plane in one pass, rows
//! in parallel; then the sensor model over whole planes (PSF, noise,
//! quantisation). No per-sample result is kept beyond its pixel, so a
//! render holds one band of samples and the planes.
//!
//! Plane values are those of the former separate passes bit for bit: a
//! mean plane is the f64 sum of the pixel's finite sample values in row
//! order divided by their count (NaN if none), rounded to f32; categorical
//! planes (material, facet, case) take the sample nearest the pixel
//! centre; the apparent temperature inverts the mean band radiance
//! ([`pixel::ApparentTempLut`]).

use std::time::Instant;

use rayon::prelude::*;
use smallvec::SmallVec;

use super::frame::{Frame, Stats};
use super::pixel::{self, ApparentTempLut, RadiometryContext, SampleResult};
use super::planes::{FIRST_TERM, PIXEL_PLANES, PLANES, Planes};
use super::prepare::{Conditions, Static};
use super::sample::Sample;
use crate::radiometry::RadianceTerms;

/// The planes filled pixel by pixel ([`PLANES`] up to `dn`).
const NP: usize = PIXEL_PLANES;

/// Each radiometric term plane from a sample's terms (the order of
/// [`super::planes::TERM_PLANES`]).
const TERMS: [fn(&RadianceTerms) -> f64; 6] = [
    |t| t.emitted,
    |t| t.reflected_solar,
    |t| t.reflected_sky_thermal + t.reflected_sky_scattered,
    |t| t.reflected_background_emitted + t.reflected_background_solar,
    |t| t.path_thermal,
    |t| t.path_scattered,
];

/// A frame's planes while its bands are rendered.
pub struct FramePlanes<'a> {
    maker: PixelMaker<'a>,
    width: u32,
    height: u32,
    /// One vector per pixel-made entry of [`PLANES`], `width`×`height`,
    /// row-major (allocated whole, zero pages until written).
    data: Vec<Vec<f32>>,
    /// Output rows filled so far (bands come in order).
    rows_filled: u32,
}

/// The values of one output pixel (every pixel-made plane) and the
/// number of samples evaluated.
pub type PixelValues = ([f32; NP], usize);

/// A pixel of [`FramePlanes::fill_rows`]: (maker, x, row in the band,
/// worker's memo) → its values.
pub type PixelFn<'f> = dyn Fn(&PixelMaker, usize, usize, &mut pixel::EvalMemo) -> anyhow::Result<PixelValues>
    + Sync
    + 'f;

/// What [`PixelMaker::pixel`] needs beside the samples.
pub struct PixelMaker<'a> {
    st: &'a Static,
    interval_h: f64,
    lut: ApparentTempLut,
}

impl<'a> FramePlanes<'a> {
    /// Empty planes of a `width`×`height` output image (filled band by
    /// band, in order, by [`Self::fill_band`]).
    pub fn new(st: &'a Static, cond: &Conditions, width: u32, height: u32) -> Self {
        let npx = width as usize * height as usize;
        FramePlanes {
            width,
            height,
            data: (0..NP).map(|_| vec![0.0; npx]).collect(),
            rows_filled: 0,
            maker: PixelMaker {
                st,
                interval_h: cond.interval_s as f64 / 3600.0,
                lut: ApparentTempLut::new(&st.band),
            },
        }
    }

    /// Fills the output rows from `row0` on from a band of samples
    /// (`sample_width` wide, row-major, a whole number of n×n pixel rows);
    /// returns the number of samples whose radiometry was evaluated.
    pub fn fill_band(
        &mut self,
        ctx: &RadiometryContext,
        band: &[Sample],
        sample_width: u32,
        row0: u32,
        n: u32,
        done: &(dyn Fn(u64) + Sync),
    ) -> anyhow::Result<u64> {
        let (sw, n, w) = (sample_width as usize, n as usize, self.width as usize);
        let rows = band.len() / (sw * n);
        let per_row = (w * n * n) as u64;
        self.fill_rows(row0, rows, &|| done(per_row), &|maker, x, r, memo| {
            if n == 1 {
                maker.pixel(ctx, &[&band[r * sw + x]], 1, memo)
            } else {
                let px: SmallVec<[&Sample; 16]> = (0..n)
                    .flat_map(|j| (0..n).map(move |i| &band[(r * n + j) * sw + x * n + i]))
                    .collect();
                maker.pixel(ctx, &px, n, memo)
            }
        })
    }

    /// Fills output rows `row0..row0 + rows` (the next ones), rows in
    /// parallel, pixel `x` of row `row0 + r` with `pixel(maker, x, r,
    /// memo)`'s values (a worker's memo); `row_done` is called after each
    /// row. Returns the sum of the evaluated-sample counts.
    pub fn fill_rows(
        &mut self,
        row0: u32,
        rows: usize,
        row_done: &(dyn Fn() + Sync),
        pixel: &PixelFn,
    ) -> anyhow::Result<u64> {
        let w = self.width as usize;
        // Bands come in order and fill whole rows.
        anyhow::ensure!(
            row0 == self.rows_filled && (row0 as usize + rows) <= self.height as usize,
            "bands out of order"
        );
        let maker = &self.maker;
        // Each output row's slice of every plane, written in place by the
        // row's worker (no per-row staging and no second pass).
        let span = row0 as usize * w..(row0 as usize + rows) * w;
        let mut row_planes: Vec<Vec<&mut [f32]>> =
            (0..rows).map(|_| Vec::with_capacity(NP)).collect();
        for plane in &mut self.data {
            for (r, chunk) in plane[span.clone()].chunks_mut(w).enumerate() {
                row_planes[r].push(chunk);
            }
        }
        let evaluated = row_planes
            .into_par_iter()
            .enumerate()
            .map(|(r, mut out)| -> anyhow::Result<u64> {
                super::cancel::check()?;
                let mut evaluated = 0u64;
                let mut memo = pixel::EvalMemo::default();
                for x in 0..w {
                    let (v, e) = pixel(maker, x, r, &mut memo)?;
                    for (plane, v) in out.iter_mut().zip(v) {
                        plane[x] = v;
                    }
                    evaluated += e as u64;
                }
                row_done();
                Ok(evaluated)
            })
            .collect::<anyhow::Result<Vec<u64>>>()?;
        self.rows_filled += rows as u32;
        Ok(evaluated.iter().sum())
    }

    /// What makes a pixel's values (see [`PixelMaker::pixel`]).
    pub fn maker(&self) -> &PixelMaker<'a> {
        &self.maker
    }

    /// Ends a frame: the planes finished ([`Self::finish`]: the sensor
    /// chain), checked finite, the sensor's time counted in `stats`; with
    /// the `samples` kept (`sample_width` wide).
    pub fn into_frame(
        self,
        mut stats: Stats,
        samples: Vec<Sample>,
        sample_width: u32,
    ) -> anyhow::Result<Frame> {
        let t = Instant::now();
        let planes = self.finish()?;
        pixel::check_finite(&planes)?;
        stats.seconds.sensor = t.elapsed().as_secs_f64();
        Ok(Frame {
            planes,
            stats,
            samples,
            sample_width,
        })
    }

    /// The finished planes: the per-pixel planes, then what the sensor
    /// chain ([`crate::sensor::apply`]: PSF, noise, quantisation → `dn`)
    /// makes of the band radiance, as `sensor_radiance`.
    pub fn finish(self) -> anyhow::Result<Planes> {
        let st = self.maker.st;
        anyhow::ensure!(self.rows_filled == self.height, "planes not filled");
        let (w, h) = (self.width, self.height);
        let mut p = Planes::new(w, h);
        let band_radiance = self.data[0].clone();
        for ((name, unit), data) in PLANES.iter().zip(self.data) {
            p.push(name, unit, data);
        }
        let sensed = crate::sensor::apply(
            band_radiance,
            w as usize,
            h as usize,
            &st.scene.scene.sensor,
            st.scene.psf_kernel.as_ref(),
        )?;
        if let Some(dn) = sensed.dn {
            let (name, unit) = PLANES[NP];
            p.push(name, unit, dn);
        }
        let (name, unit) = PLANES[NP + 1];
        p.push(name, unit, sensed.radiance);
        Ok(p)
    }
}

impl PixelMaker<'_> {
    /// Every pixel-made [`PLANES`] value of one output pixel from its n×n
    /// samples (row-major); also the number of samples evaluated.
    pub fn pixel(
        &self,
        ctx: &RadiometryContext,
        px: &[&Sample],
        n: usize,
        memo: &mut pixel::EvalMemo,
    ) -> anyhow::Result<PixelValues> {
        self.pixel_shared(ctx, px, None, n, memo)
    }

    /// [`Self::pixel`] where positions of the n×n grid may share one
    /// sample (adaptive sampling's unrefined cells: [`super::adaptive`]):
    /// `owner[k]` is the position whose sample's radiometry position `k`
    /// uses (its own for a sample of its own; an owner is its own owner),
    /// each owner evaluated once and weighted by its positions.
    pub fn pixel_shared(
        &self,
        ctx: &RadiometryContext,
        px: &[&Sample],
        owner: Option<&[usize]>,
        n: usize,
        memo: &mut pixel::EvalMemo,
    ) -> anyhow::Result<PixelValues> {
        let c = (n / 2) * n + n / 2;
        let np = px.len();
        let uniform = n == 1 || pixel::representatives(px, n as u32)[0] == c;
        // The distinct results (each owner's, evaluated once) and how many
        // positions each stands for; `centre` is the centre position's.
        let mut results: SmallVec<[SampleResult; 1]> = SmallVec::new();
        let mut weight: SmallVec<[u32; 1]> = SmallVec::new();
        let centre = if uniform {
            results.push(ctx.evaluate_memo(px[c], memo)?);
            weight.push(np as u32);
            0
        } else {
            // (an owner may come after the positions it stands for)
            let mut of = vec![u32::MAX; np];
            for k in 0..np {
                let o = owner.map_or(k, |o| o[k]);
                if of[o] == u32::MAX {
                    of[o] = results.len() as u32;
                    results.push(ctx.evaluate_memo(px[o], memo)?);
                    weight.push(0);
                }
                weight[of[o] as usize] += 1;
            }
            of[owner.map_or(c, |o| o[c])] as usize
        };
        let evaluated = results.len();
        // The positions' mean of a result's value: each distinct result
        // weighted by its positions (non-finite values left out).
        let wmean = |f: &dyn Fn(&SampleResult) -> f64| -> f32 {
            let (mut s, mut finite) = (0.0, 0u32);
            for (r, &w) in results.iter().zip(&weight) {
                let v = f(r);
                if v.is_finite() {
                    s += v * w as f64;
                    finite += w;
                }
            }
            if finite > 0 {
                (s / finite as f64) as f32
            } else {
                f32::NAN
            }
        };
        // The positions in runs of one sample (an unrefined cell's sample
        // stands for its row of positions, a pixel's for all): each plane's
        // mean over the positions is a mean over the runs weighted by their
        // lengths, each sample's value computed once per run.
        let mut runs: SmallVec<[(usize, u32); 16]> = SmallVec::new();
        for k in 0..np {
            match runs.last_mut() {
                Some((first, len)) if std::ptr::eq(px[*first], px[k]) => *len += 1,
                _ => runs.push((k, 1)),
            }
        }
        // (generic, not `&dyn Fn`: each plane's closure is inlined)
        fn mean_runs(runs: &[(usize, u32)], px: &[&Sample], f: impl Fn(&Sample) -> f64) -> f32 {
            let (mut s, mut finite) = (0.0, 0u32);
            for &(k, len) in runs {
                let v = f(px[k]);
                if v.is_finite() {
                    s += v * len as f64;
                    finite += len;
                }
            }
            if finite > 0 {
                (s / finite as f64) as f32
            } else {
                f32::NAN
            }
        }
        let surf = |k: usize| px[k].surface.as_ref();
        let radiance = wmean(&|r| r.radiance_w_m2_sr_um);
        let band = &self.st.band;
        let t_app = memo.apparent.get_or(radiance.to_bits(), || {
            self.lut
                .apparent_temp_k(band, radiance as f64)
                .map_or(f32::NAN, |t| t as f32)
        });
        let mut v = [0f32; NP];
        v[0] = radiance;
        v[1] = t_app;
        v[2] = mean_runs(&runs, px, |p| {
            p.surface.as_ref().map_or(f64::NAN, |s| s.temp_k)
        });
        v[3] = surf(c).map_or(-1.0, |s| s.material as f64) as f32;
        v[4] = surf(c).map_or(-1.0, |s| s.prim as f64) as f32;
        v[5] = mean_runs(&runs, px, |p| {
            p.surface
                .as_ref()
                .map_or(f64::NAN, |s| s.sun_now() as u8 as f64)
        });
        v[6] = mean_runs(&runs, px, |p| {
            p.surface.as_ref().map_or(f64::NAN, |s| {
                s.history.count_sunlit() as f64 * self.interval_h
            })
        });
        v[7] = mean_runs(&runs, px, |p| {
            p.surface.as_ref().map_or(f64::NAN, |s| s.range_m as f64)
        });
        // The hit point in the tracer's local frame: world coordinates minus
        // the frame's origin (`scene::frame`), which the georeferencing
        // states as its ground origin (f32 keeps 0.5 mm within 16 km of it).
        for axis in 0..3 {
            v[8 + axis] = mean_runs(&runs, px, |p| {
                p.surface
                    .as_ref()
                    .map_or(f64::NAN, |s| s.point[axis] as f64)
            });
        }
        // (the view angle is geometry: each position's own sample's, as the
        // range and ground point, also where a donor's radiometry stands
        // for it)
        v[11] = if uniform {
            wmean(&|r| r.view_angle_deg)
        } else {
            mean_runs(&runs, px, |p| p.view_angle_deg())
        };
        v[12] = results[centre].case as f32;
        for (t, f) in TERMS.iter().enumerate() {
            v[FIRST_TERM + t] = wmean(&|r| f(&r.terms));
        }
        Ok((v, evaluated))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::planes::{PLANE_NAMES, TERM_PLANES};

    /// The indices [`FramePlanes::pixel`] and [`FramePlanes::finish`] write
    /// are the planes [`PLANES`] names there.
    #[test]
    fn pixel_values_land_in_their_named_planes() {
        let at = [
            (0, "band_radiance"),
            (1, "apparent_temperature"),
            (2, "surface_temperature"),
            (3, "material"),
            (4, "facet"),
            (5, "sun_now"),
            (6, "hours_sunlit"),
            (7, "range"),
            (8, "ground_x"),
            (10, "ground_z"),
            (11, "view_angle"),
            (12, "case"),
            (FIRST_TERM, "emitted"),
            (NP - 1, "path_scattered"),
            (NP, "dn"),
            (NP + 1, "sensor_radiance"),
        ];
        for (i, name) in at {
            assert_eq!(PLANE_NAMES[i], name, "plane {i}");
        }
        assert_eq!(TERM_PLANES.len(), TERMS.len());
        assert_eq!(FIRST_TERM + TERMS.len(), NP);
    }
}
