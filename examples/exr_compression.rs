//! Measures the EXR writer's lossless compressions on a rendered frame: for
//! each, the best-of-N write time (blocks compressed in parallel on the
//! rayon pool, as `irsig render` writes), the process CPU time of that
//! write (user + system, Linux /proc; steadier than the wall time on a
//! shared machine) and the file size, and checks that the planes read back
//! bit for bit. BENCHMARKS.md, "EXR compression".
//!
//! `cargo run --release --example exr_compression -- x.exr [repeats]`
//! (x.exr: any `irsig render` output; its planes are written again).

use std::time::Instant;

use irsig::output::exr::{ExrCompression, read_exr, write_exr};
use irsig::output::{OutputSet, Planes};

/// The process's CPU time (user + system), s, from /proc/self/stat (Linux;
/// 0 elsewhere).
fn cpu_s() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the parenthesised command name; utime and stime are the
    // 14th and 15th fields of the line, in clock ticks (100 per second).
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<f64> = rest
        .split_whitespace()
        .skip(11)
        .take(2)
        .filter_map(|v| v.parse().ok())
        .collect();
    f.iter().sum::<f64>() / 100.0
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let input = args
        .get(1)
        .ok_or("usage: exr_compression x.exr [repeats]")?;
    let repeats: usize = args.get(2).map_or(Ok(5), |s| s.parse())?;
    let (w, h, chans) = read_exr(std::path::Path::new(input))?;
    let mut planes = Planes::new(w, h);
    for (name, data) in chans {
        planes.push(&name, "", data);
    }
    let mib = (w as f64) * (h as f64) * 4.0 * planes.planes.len() as f64 / (1 << 20) as f64;
    println!(
        "{input}: {w}x{h}, {} planes, {mib:.0} MiB of samples, best of {repeats}",
        planes.planes.len()
    );
    println!(
        "| compression | write s | write CPU s | read s | MiB | size / uncompressed | write s x MiB |"
    );
    println!("|---|---|---|---|---|---|---|");
    let dir = tempfile::tempdir()?;
    let mut none_mib = None;
    for c in ExrCompression::ALL {
        let path = dir.path().join(format!("{c}.exr"));
        let (mut best, mut cpu) = (f64::INFINITY, f64::INFINITY);
        for _ in 0..repeats {
            let (t, c0) = (Instant::now(), cpu_s());
            let mut set = OutputSet::new(&path)?;
            write_exr(&mut set, &path, &planes, &[], c)?;
            set.commit()?;
            best = best.min(t.elapsed().as_secs_f64());
            cpu = cpu.min(cpu_s() - c0);
        }
        let size = std::fs::metadata(&path)?.len() as f64 / (1 << 20) as f64;
        let none = *none_mib.get_or_insert(size);
        let t = Instant::now();
        let (_, _, back) = read_exr(&path)?;
        let read = t.elapsed().as_secs_f64();
        for (p, (_, d)) in planes.planes.iter().zip(&back) {
            let same = p.data.len() == d.len()
                && p.data
                    .iter()
                    .zip(d)
                    .all(|(a, b)| a.to_bits() == b.to_bits());
            if !same {
                return Err(format!("{c}: {} does not read back bit for bit", p.name).into());
            }
        }
        println!(
            "| {c} | {best:.3} | {cpu:.2} | {read:.2} | {size:.1} | {:.2} | {:.1} |",
            size / none,
            best * size
        );
    }
    zlib_levels(&planes, repeats);
    Ok(())
}

/// The ZIPS blocks of the frame (one scan line of every channel, in the
/// file's channel order) compressed in parallel with irsig's
/// `exr_zip::compress` at zlib-rs levels 1-9, and with miniz_oxide at level
/// 4 (the exr crate's own ZIP compression): best-of-N wall time and the
/// compressed size (compression alone, no file write).
fn zlib_levels(planes: &Planes, repeats: usize) {
    use rayon::prelude::*;
    let (w, h) = (planes.width as usize, planes.height as usize);
    let mut chans: Vec<(String, &[f32])> = planes
        .planes
        .iter()
        .map(|p| (irsig::output::exr::channel_name(&p.name), &p.data[..]))
        .collect();
    chans.sort_by(|a, b| a.0.cmp(&b.0));
    let blocks: Vec<Vec<u8>> = (0..h)
        .map(|y| {
            chans
                .iter()
                .flat_map(|(_, d)| d[y * w..(y + 1) * w].iter().flat_map(|v| v.to_le_bytes()))
                .collect()
        })
        .collect();
    let raw: usize = blocks.iter().map(Vec::len).sum();
    let mib = |b: usize| b as f64 / (1 << 20) as f64;
    println!();
    println!(
        "ZIPS blocks alone ({h} blocks, {:.1} MiB), compressed in parallel, best of {repeats}:",
        mib(raw)
    );
    println!();
    println!("| zlib | compress s | MiB | size / uncompressed | compress s x MiB |");
    println!("|---|---|---|---|---|");
    let run = |name: &str, f: &(dyn Fn(&[u8]) -> Vec<u8> + Sync)| {
        let (mut best, mut size) = (f64::INFINITY, 0);
        for _ in 0..repeats {
            let t = Instant::now();
            let out: Vec<Vec<u8>> = blocks.par_iter().map(|b| f(b)).collect();
            best = best.min(t.elapsed().as_secs_f64());
            size = out.iter().map(Vec::len).sum();
        }
        println!(
            "| {name} | {best:.3} | {:.1} | {:.3} | {:.1} |",
            mib(size),
            size as f64 / raw as f64,
            best * mib(size)
        );
    };
    run("miniz_oxide 4 (exr crate)", &|b| {
        let z = miniz_oxide::deflate::compress_to_vec_zlib(&irsig::output::exr_zip::predict(b), 4);
        if z.len() < b.len() { z } else { b.to_vec() }
    });
    for level in 1..=9 {
        run(&format!("zlib-rs {level}"), &|b| {
            irsig::output::exr_zip::compress(b.to_vec(), level)
        });
    }
}
