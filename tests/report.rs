//! Seeing a render: the PNG quicklook's colour bar, minimum stretch span
//! and colour maps, and `irsig report`'s self-contained HTML page, opened
//! in headless Chromium (Debian's `chromium`, installed by
//! scripts/setup.sh): a screenshot shows the drawn planes, and a scripted
//! hover reads back known pixel values.

mod common;
use common::succeed;

use std::path::{Path, PathBuf};
use std::process::Command;

use irsig::output::frame::min_span_radiance;
use irsig::output::quicklook::{
    Colormap, QuicklookStyle, Stretch, compose, label_number, with_min_span,
};

fn irsig() -> Command {
    Command::new(env!("CARGO_BIN_EXE_irsig"))
}

fn plate() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/plate/scene.toml")
}

#[test]
fn inferno_matches_matplotlib_and_grey_is_linear() {
    // matplotlib's inferno at 0, 0.5 and 1 (matplotlib._cm_listed).
    assert_eq!(Colormap::Inferno.colour(0.0), [0, 0, 4]);
    assert_eq!(Colormap::Inferno.colour(0.5), [188, 55, 84]);
    assert_eq!(Colormap::Inferno.colour(1.0), [252, 255, 164]);
    assert_eq!(Colormap::Grey.colour(0.5), [128, 128, 128]);
    assert_eq!(Colormap::Grey.colour(f64::NAN), [0, 0, 0]);
    // Inferno's lightness rises monotonically (Rec. 709 luma as a proxy).
    let luma = |c: [u8; 3]| 0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64;
    let l: Vec<f64> = (0..=64)
        .map(|i| luma(Colormap::Inferno.colour(i as f64 / 64.0)))
        .collect();
    assert!(l.windows(2).all(|w| w[1] > w[0]), "{l:?}");
}

#[test]
fn min_span_widens_about_the_centre_and_is_2k_of_planck() {
    let s = with_min_span(Stretch { lo: 10.0, hi: 11.0 }, 4.0);
    assert_eq!(s, Stretch { lo: 8.5, hi: 12.5 });
    let wide = Stretch { lo: 0.0, hi: 10.0 };
    assert_eq!(with_min_span(wide, 4.0), wide);
    // 2 K about 300 K in 8-14 um: 2 K x dB/dT averaged over the band,
    // dB/dT from Planck's analytic derivative (trapezoid, 0.001 um steps);
    // B is nearly linear over 2 K, so they agree to 1e-4.
    let temps = vec![299.0f32, 300.0, 300.0, 301.0, f32::NAN];
    let span = min_span_radiance(&temps, (8.0, 14.0), 2.0) as f64;
    let n = 6000;
    let mut integral = 0.0;
    for i in 0..=n {
        let l = 8.0 + 6.0 * i as f64 / n as f64;
        let wgt = if i == 0 || i == n { 0.5 } else { 1.0 };
        integral += wgt * irsig::radiometry::planck::planck_dt_w_m2_sr_um_k(l, 300.0);
    }
    let want = 2.0 * integral * (6.0 / n as f64) / 6.0;
    assert!((span - want).abs() < 1e-4 * want, "span {span} want {want}");
    assert_eq!(min_span_radiance(&[f32::NAN], (8.0, 14.0), 2.0), 0.0);
}

#[test]
fn quicklook_draws_the_image_a_colour_bar_and_labels() {
    let (w, h) = (8u32, 4u32);
    let data: Vec<f32> = (0..32).map(|i| 280.0 + i as f32 * 0.1).collect();
    let s = Stretch {
        lo: 280.0,
        hi: 283.1,
    };
    let style = QuicklookStyle {
        colormap: Colormap::Inferno,
        min_span: 0.0,
        caption: "t [K]".into(),
    };
    let (cw, ch, px) = compose(w, h, &data, s, &style);
    // Widened for the labels "280.0" .. "283.1" and the caption.
    assert!(cw as usize >= (label_number(280.0).len() + label_number(283.1).len() + 2) * 6);
    assert!(ch > h + 20);
    let at = |x: u32, y: u32| {
        let i = 3 * (y * cw + x) as usize;
        [px[i], px[i + 1], px[i + 2]]
    };
    for (i, &v) in data.iter().enumerate() {
        let (x, y) = (i as u32 % w, i as u32 / w);
        let t = ((v - s.lo) / (s.hi - s.lo)) as f64;
        assert_eq!(at(x, y), Colormap::Inferno.colour(t), "pixel {x},{y}");
    }
    // Right of the image: black; the bar runs from colour(0) to colour(1).
    assert_eq!(at(w + 2, 1), [0, 0, 0]);
    let bar_y = h + 4 + 5;
    assert_eq!(at(2, bar_y), Colormap::Inferno.colour(0.0));
    assert_eq!(at(cw - 3, bar_y), Colormap::Inferno.colour(1.0));
    // Labels: white pixels under the bar, none above it beside the image.
    let white = (0..cw)
        .flat_map(|x| (bar_y + 6..ch).map(move |y| (x, y)))
        .filter(|&(x, y)| at(x, y) == [255, 255, 255])
        .count();
    assert!(white > 40, "{white} label pixels");
    assert_eq!(label_number(281.04), "281.0");
    assert_eq!(label_number(0.000123), "1.230e-4");
}

/// Debian's `chromium`, or `$IRSIG_CHROMIUM`.
fn chromium() -> PathBuf {
    if let Some(p) = std::env::var_os("IRSIG_CHROMIUM") {
        return p.into();
    }
    for name in ["chromium", "chromium-browser", "google-chrome"] {
        for dir in std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default()) {
            if dir.join(name).is_file() {
                return dir.join(name);
            }
        }
    }
    panic!(
        "no chromium on PATH: the report test opens the page in headless Chromium (scripts/setup.sh installs Debian's chromium; or set IRSIG_CHROMIUM)"
    );
}

/// Runs headless Chromium on `url` with `extra` flags (a fresh profile,
/// no network services), at most 120 s; returns stdout.
fn run_chromium(url: &str, extra: &[String], profile: &Path) -> String {
    let out = Command::new("timeout")
        .arg("120")
        .arg(chromium())
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--no-first-run",
            "--hide-scrollbars",
            "--virtual-time-budget=10000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(extra)
        .arg(url)
        .output()
        .expect("chromium runs");
    assert!(
        out.status.success(),
        "chromium failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The text of the element `id` in a dumped DOM.
fn element_text(dom: &str, id: &str) -> String {
    let open = format!("id=\"{id}\">");
    let start = dom
        .find(&open)
        .unwrap_or_else(|| panic!("no #{id} in the DOM"))
        + open.len();
    let end = dom[start..].find('<').unwrap() + start;
    dom[start..end].to_string()
}

#[test]
fn report_page_draws_planes_and_reads_back_hovered_values_in_chromium() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("p.exr");
    succeed(
        irsig()
            .arg("render")
            .arg(plate())
            .arg("-o")
            .arg(&exr)
            .args(["-q", "--colormap", "inferno"])
            .args([
                "--set",
                "sensor.width_px=40",
                "--set",
                "sensor.height_px=24",
            ]),
    );
    let json = exr.with_extension("json");
    let out = irsig().arg("report").arg(&json).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let html_path = json.with_extension("html");
    let html = std::fs::read_to_string(&html_path).unwrap();
    // Self-contained: nothing is fetched (no URL, no src/href attribute)
    // and the page's policy forbids it.
    for bad in ["http://", "https://", " src=", " href=", "@import"] {
        assert!(!html.contains(bad), "the page holds {bad}");
    }
    assert!(html.contains("default-src 'none'"));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    for m in summary["materials"].as_array().unwrap() {
        assert!(html.contains(m["name"].as_str().unwrap()));
    }
    for key in ["Sun", "Sensor", "Atmosphere", "sun zenith (deg)"] {
        assert!(html.contains(key), "{key}");
    }

    let (w, _h, chans) = irsig::output::exr::read_exr(&exr).unwrap();
    let plane = |n: &str| &chans.iter().find(|c| c.0 == n).unwrap().1;
    let (col, row) = (17usize, 9usize);
    let t = plane("apparent_temperature")[row * w as usize + col];
    let m = plane("material")[row * w as usize + col];
    assert!(t.is_finite() && m >= 0.0);
    let url = |hover: &str| format!("file://{}#hover={hover}", html_path.display());

    // A scripted hover over pixel (17, 9) of apparent_temperature: the
    // page's own mousemove handler writes the value under the cursor.
    let dom = run_chromium(
        &url(&format!("apparent_temperature:{col}:{row}")),
        &["--dump-dom".into()],
        &dir.path().join("profile1"),
    );
    let text = element_text(&dom, "readout-apparent_temperature");
    let prefix = format!("apparent_temperature ({col}, {row}) = ");
    assert!(text.starts_with(&prefix), "{text}");
    let v: f64 = text[prefix.len()..]
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(
        (v - t as f64).abs() <= 1e-6 * (t as f64).abs(),
        "read {v}, pixel holds {t}"
    );
    assert!(text.ends_with(" K"), "{text}");
    let dom = run_chromium(
        &url(&format!("material:{col}:{row}")),
        &["--dump-dom".into()],
        &dir.path().join("profile2"),
    );
    let text = element_text(&dom, "readout-material");
    let name = summary["materials"][m as usize]["name"].as_str().unwrap();
    assert!(
        text.starts_with(&format!("material ({col}, {row}) = {m}"))
            && text.ends_with(&format!("({name})")),
        "{text}"
    );

    // A screenshot: the planes are drawn (many inferno-coloured pixels:
    // red well above blue, as no grey text or background is).
    let shot = dir.path().join("shot.png");
    run_chromium(
        &url("none:0:0"),
        &[
            format!("--screenshot={}", shot.display()),
            "--window-size=1200,2400".into(),
        ],
        &dir.path().join("profile3"),
    );
    let dec = png::Decoder::new(std::fs::File::open(&shot).unwrap());
    let mut reader = dec.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let ch = info.color_type.samples();
    let coloured = buf[..info.buffer_size()]
        .chunks_exact(ch)
        .filter(|p| p[0] as i32 - p[2] as i32 > 60)
        .count();
    assert!(
        coloured > 2000,
        "{coloured} coloured pixels in the screenshot"
    );
}

#[test]
fn report_refuses_what_is_not_a_render_summary() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("x.json");
    std::fs::write(&bad, "{\"a\": 1}").unwrap();
    let out = irsig().arg("report").arg(&bad).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("x.json") && err.contains("not a render's JSON summary"),
        "{err}"
    );
    assert!(!dir.path().join("x.html").exists());
}

/// The planes a report page embeds: name → values (the page's JSON block,
/// base64 float32 decoded).
fn embedded_planes(html: &str) -> Vec<(String, Vec<f32>)> {
    use base64::Engine;
    let open = "<script type=\"application/json\" id=\"irsig-data\">";
    let start = html.find(open).unwrap() + open.len();
    let end = html[start..].find("</script>").unwrap() + start;
    let v: serde_json::Value = serde_json::from_str(&html[start..end]).unwrap();
    v["planes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let bytes = base64::engine::general_purpose::STANDARD
                .decode(p["data"].as_str().unwrap())
                .unwrap();
            let vals = bytes
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect();
            (p["name"].as_str().unwrap().to_string(), vals)
        })
        .collect()
}

#[test]
fn report_reads_a_geotiff_set_as_it_reads_an_exr_set() {
    // The same render written as an EXR set and as a GeoTIFF set: the
    // pages embed bit-identical planes, in the JSON's order; --planes
    // picks and orders them, and an unknown plane is refused by name.
    let dir = tempfile::tempdir().unwrap();
    let mut pages = Vec::new();
    for out in ["e.exr", "g.tif"] {
        let path = dir.path().join(out);
        let r = irsig()
            .arg("render")
            .arg(plate())
            .arg("-o")
            .arg(&path)
            .args([
                "-q",
                "--set",
                "sensor.width_px=20",
                "--set",
                "sensor.height_px=12",
            ])
            .output()
            .unwrap();
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let html = dir.path().join(format!("{out}.html"));
        let r = irsig()
            .arg("report")
            .arg(path.with_extension("json"))
            .arg("-o")
            .arg(&html)
            .args(["--planes", "material,apparent_temperature,range"])
            .output()
            .unwrap();
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        pages.push(embedded_planes(&std::fs::read_to_string(&html).unwrap()));
    }
    let names: Vec<&str> = pages[0].iter().map(|p| p.0.as_str()).collect();
    assert_eq!(names, ["material", "apparent_temperature", "range"]);
    for (a, b) in pages[0].iter().zip(&pages[1]) {
        assert_eq!(a.0, b.0);
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a.1), bits(&b.1), "{}", a.0);
        assert_eq!(a.1.len(), 20 * 12);
    }
    let r = irsig()
        .arg("report")
        .arg(dir.path().join("g.json"))
        .args(["--planes", "temprature"])
        .output()
        .unwrap();
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("--planes temprature") && err.contains("apparent_temperature"),
        "{err}"
    );
}
