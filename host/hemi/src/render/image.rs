//! The image pass 2 makes, and what becomes of it: exposure, tone map and the image files.

use anyhow::{Context, Result};
use std::io::Write;
use std::path::Path;

/// A linear-radiance image (W/(m²·sr) per channel), row-major from the top-left.
#[derive(Clone, Debug)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Pixel radiances.
    pub pixels: Vec<[f32; 3]>,
}

/// Auto exposure puts this percentile of the lit luminances …
pub const EXPOSED_PERCENTILE: f64 = 0.95;
/// … at this fraction of full scale.
pub const EXPOSED_LEVEL: f64 = 0.85;

/// Luminance of a linear RGB radiance (Rec. 709 weights).
pub fn luminance(p: &[f32; 3]) -> f32 {
    0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]
}

/// The automatic exposure, in stops: the 95th percentile of the lit pixels' luminance is put at
/// 0.85 of full scale, so surfaces keep their shading and only the brightest few per cent (the
/// lights) clip.
pub fn auto_exposure(img: &Image) -> f64 {
    exposure_for(img.pixels.iter().copied())
}

/// The automatic exposure of [`auto_exposure`] for any set of equally weighted radiances.
pub fn exposure_for(radiances: impl Iterator<Item = [f32; 3]>) -> f64 {
    let mut lum: Vec<f32> = radiances
        .map(|p| luminance(&p))
        .filter(|l| *l > 0.0)
        .collect();
    if lum.is_empty() {
        return 0.0;
    }
    lum.sort_by(f32::total_cmp);
    let p95 = lum[((lum.len() - 1) as f64 * EXPOSED_PERCENTILE) as usize] as f64;
    (EXPOSED_LEVEL / p95).log2()
}

/// A linear value in [0, 1] (clipped) encoded as an 8-bit sRGB code.
pub fn srgb8(x: f64) -> u8 {
    let x = x.clamp(0.0, 1.0);
    let v = if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    };
    (v * 255.0 + 0.5) as u8
}

/// Writes an 8-bit sRGB PNG file: radiance × 2^exposure, clipped, sRGB-encoded.
pub fn write_png(img: &Image, exposure: f64, path: &Path) -> Result<()> {
    let file =
        std::fs::File::create(path).with_context(|| format!("cannot create {}", path.display()))?;
    let mut out = std::io::BufWriter::new(file);
    write_png_to(img, exposure, &mut out)
        .with_context(|| format!("cannot write {}", path.display()))
}

/// Writes the PNG of [`write_png`] to `out` (a file, or stdout for `-o -`).
pub fn write_png_to(img: &Image, exposure: f64, out: &mut dyn Write) -> Result<()> {
    let scale = 2f64.powf(exposure);
    let data: Vec<u8> = img
        .pixels
        .iter()
        .flat_map(|p| {
            [
                srgb8(p[0] as f64 * scale),
                srgb8(p[1] as f64 * scale),
                srgb8(p[2] as f64 * scale),
            ]
        })
        .collect();
    let mut enc = png::Encoder::new(&mut *out, img.width, img.height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let mut writer = enc.write_header()?;
    writer.write_image_data(&data)?;
    writer.finish()?;
    out.flush()?;
    Ok(())
}

/// Writes the linear radiances as an OpenEXR file (32-bit float RGB).
pub fn write_exr(img: &Image, path: &Path) -> Result<()> {
    let w = img.width as usize;
    exr::prelude::write_rgb_file(path, w, img.height as usize, |x, y| {
        let p = img.pixels[y * w + x];
        (p[0], p[1], p[2])
    })
    .with_context(|| format!("cannot write {}", path.display()))
}

/// Reads an 8-bit RGB PNG back (tests and golden images).
pub fn read_png(path: &Path) -> Result<(u32, u32, Vec<u8>)> {
    let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path)?));
    let mut reader = dec.read_info()?;
    let mut buf = vec![0; reader.output_buffer_size().context("PNG too large")?];
    let info = reader.next_frame(&mut buf)?;
    anyhow::ensure!(
        info.color_type == png::ColorType::Rgb && info.bit_depth == png::BitDepth::Eight,
        "expected 8-bit RGB"
    );
    buf.truncate(info.buffer_size());
    Ok((info.width, info.height, buf))
}
