//! The image as a Radiance picture (`.hdr`, RGBE): the format `ximage`, `pfilt`, `falsecolor`
//! and `evalglare` read, so a render can go on through Radiance's tools.
//!
//! Each pixel is a shared exponent and three 8-bit mantissas (Ward's RGBE), in the radiance
//! units of pass 2 (W/(m²·sr)). Scanlines are written in the run-length encoding Radiance itself
//! writes, as literal runs only: that is valid for every reader and never ambiguous, while a
//! flat scanline could be mistaken for an encoded one. (Widths outside 8..=32767 cannot be
//! encoded and are written flat, with the one ambiguous pixel value rewritten exactly.) The
//! encoder is short enough not to need an image crate; tests read its files with one.

use super::image::Image;
use anyhow::Context;
use std::io::{Result, Write};
use std::path::Path;

/// Writes the linear radiances of `img` as a Radiance picture file.
pub fn write_hdr(img: &Image, path: &Path) -> anyhow::Result<()> {
    let file =
        std::fs::File::create(path).with_context(|| format!("cannot create {}", path.display()))?;
    let mut out = std::io::BufWriter::new(file);
    write_hdr_to(img, &mut out)
        .and_then(|()| out.flush())
        .with_context(|| format!("cannot write {}", path.display()))
}

/// Writes `img` as a Radiance picture to `out`.
pub fn write_hdr_to(img: &Image, out: &mut dyn Write) -> Result<()> {
    let (w, h) = (img.width as usize, img.height as usize);
    write!(
        out,
        "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nSOFTWARE=hemi\n\n-Y {h} +X {w}\n"
    )?;
    let encoded = (8..=0x7fff).contains(&w);
    let mut planes = [vec![0u8; w], vec![0u8; w], vec![0u8; w], vec![0u8; w]];
    for row in img.pixels.chunks_exact(w.max(1)) {
        if !encoded {
            for p in row {
                out.write_all(&flat(rgbe(*p)))?;
            }
            continue;
        }
        for (x, p) in row.iter().enumerate() {
            for (plane, byte) in planes.iter_mut().zip(rgbe(*p)) {
                plane[x] = byte;
            }
        }
        out.write_all(&[2, 2, (w >> 8) as u8, (w & 0xff) as u8])?;
        for plane in &planes {
            for chunk in plane.chunks(128) {
                out.write_all(&[chunk.len() as u8])?;
                out.write_all(chunk)?;
            }
        }
    }
    Ok(())
}

/// One pixel's RGBE: mantissas m·256/2^e of the channels for the exponent e of the largest,
/// biased by 128; black (and anything below 1e-32) is all zeros. Negative values are clipped.
fn rgbe(p: [f32; 3]) -> [u8; 4] {
    let p = p.map(|x| {
        if x.is_finite() {
            x.max(0.0) as f64
        } else {
            0.0
        }
    });
    let v = p[0].max(p[1]).max(p[2]);
    if v < 1e-32 {
        return [0; 4];
    }
    // v = m · 2^e with m in [0.5, 1)
    let mut e = v.log2().floor() as i32 + 1;
    if v / 2f64.powi(e) >= 1.0 {
        e += 1;
    }
    let scale = 256.0 / 2f64.powi(e);
    let m = p.map(|x| ((x * scale) as u32).min(255) as u8);
    [m[0], m[1], m[2], (e + 128).clamp(0, 255) as u8]
}

/// A pixel for a flat scanline: (1, 1, 1, e) would read as an old-style run, so it is written
/// as the equal (2, 2, 2, e − 1).
fn flat(p: [u8; 4]) -> [u8; 4] {
    match p {
        [1, 1, 1, e] if e > 0 => [2, 2, 2, e - 1],
        p => p,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgbe_keeps_the_largest_channel_to_one_part_in_256() {
        for v in [1e-20f32, 0.001, 0.5, 1.0, 3.7, 1e6] {
            let [r, g, b, e] = rgbe([v, v / 2.0, 0.0]);
            let back = |m: u8| (m as f64 + 0.5) * 2f64.powi(e as i32 - 136);
            assert!((back(r) - v as f64).abs() <= v as f64 / 128.0, "{v}");
            assert!((back(g) - v as f64 / 2.0).abs() <= v as f64 / 128.0, "{v}");
            assert_eq!(b, 0);
            assert!(r >= 128, "normalised mantissa");
        }
        assert_eq!(rgbe([0.0, -1.0, f32::NAN]), [0; 4]);
    }

    #[test]
    fn the_flat_run_marker_is_rewritten_to_the_same_value() {
        assert_eq!(flat([1, 1, 1, 100]), [2, 2, 2, 99]);
        assert_eq!(flat([1, 1, 2, 100]), [1, 1, 2, 100]);
    }
}
