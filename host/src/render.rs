//! Pass 2 on the host (spec §2 step 4): eye rays through every pixel by the kernel's pixel
//! tracer, diffuse colour from the hit patch's vertex grid at the hit's (u,v), then exposure,
//! tone map and the image files.

use crate::engine::SoftEngine;
use crate::optics::{SceneOptics, Scratch};
use crate::pass1::Pass1Settings;
use crate::radiosity::Grid;
use crate::scene::Scene;
use anyhow::{Context, Result};
use hemi_kernel::accel::Accelerator;
use hemi_kernel::camera::Camera;
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::OwnedHemisphere;
use hemi_kernel::pixels::trace_pixels;
use hemi_kernel::specular::SpecularStats;
use rayon::prelude::*;
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

/// The kernel camera of a scene's `[camera]`.
pub fn camera_of(scene: &Scene) -> Result<Camera> {
    let c = scene
        .camera
        .as_ref()
        .context("the scene has no [camera] table: pass 2 needs one (spec §6)")?;
    Camera::look_at(
        c.eye,
        c.look_at,
        c.up,
        c.fov_y_deg as f32,
        c.width,
        c.height,
    )
    .context("[camera]: the view direction is zero or parallel to `up`")
}

/// Renders `scene` through `camera` with `spp` eye rays per pixel. A ray on a diffuse patch's
/// front side sees its radiance B(u,v)/π (emitters included, so a light shows its radiance); a
/// ray on a specular patch adds what its frustums see, weighted by k and the lobe (§5); back
/// sides and misses are black. `progress` gets the rows finished.
pub fn render(
    scene: &Scene,
    grids: &[Grid],
    camera: &Camera,
    spp: u32,
    settings: &Pass1Settings,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Rendered> {
    let patches = scene.kernel_patches();
    render_with(
        scene,
        grids,
        camera,
        spp,
        settings,
        &|| SoftEngine::new(&patches),
        progress,
    )
}

/// An image and what its specular frustums did.
#[derive(Clone, Debug)]
pub struct Rendered {
    /// The image.
    pub image: Image,
    /// Frustums, rays, truncation and stack use of pass 2, weights in pixel fractions summed
    /// over all eye rays.
    pub specular: SpecularStats,
}

/// Adds to pixel `px` what one of its `spp` rays shows: radiance B/π of the diffuse surface it
/// reached, times the weight the specular path passed on. Boards' hits are shaded with this
/// too, so their images equal the in-process ones bit for bit.
pub fn shade(px: &mut [f32; 3], weight: [f32; 3], b: [f64; 3], spp: u32) {
    for c in 0..3 {
        px[c] += (weight[c] as f64 * b[c] / std::f64::consts::PI / spp as f64) as f32;
    }
}

/// [`render`] with engines made by `make` (one per worker thread). Frustums are cut from the
/// hemisphere of `settings` (R) and bounded by its specular settings, as in pass 1.
pub fn render_with<A: Accelerator>(
    scene: &Scene,
    grids: &[Grid],
    camera: &Camera,
    spp: u32,
    settings: &Pass1Settings,
    make: &(dyn Fn() -> A + Sync),
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Rendered> {
    let (w, h) = (camera.width, camera.height);
    let spp = spp.max(1);
    crate::optics::check(&settings.specular)?;
    let hemi = OwnedHemisphere::new(settings.circles, settings.rule)
        .map_err(|e| anyhow::anyhow!("--circles {}: {e:?}", settings.circles))?;
    let view = hemi.view();
    let optics = SceneOptics::new(scene, &view)?;
    let kernel_optics = optics.view();
    const BATCH: usize = 4096;
    let rows: Vec<(Vec<[f32; 3]>, SpecularStats)> = (0..h)
        .into_par_iter()
        .map_init(
            || {
                (
                    make(),
                    vec![Vec3::ZERO; BATCH],
                    Scratch::new(BATCH, &settings.specular),
                )
            },
            |(accel, dirs, scratch), y| {
                let mut row = vec![[0.0f32; 3]; w as usize];
                let stats = trace_pixels(
                    accel,
                    camera,
                    &kernel_optics,
                    &view,
                    &mut scratch.view(),
                    y * w..(y + 1) * w,
                    spp,
                    dirs,
                    |p, _s, hit, weight| {
                        let b = grids[scene.side_seen(hit.patch, hit.front)].at(hit.u, hit.v);
                        shade(&mut row[(p - y * w) as usize], weight, b, spp);
                    },
                );
                progress(1);
                (row, stats)
            },
        )
        .collect();
    let mut specular = SpecularStats::default();
    let mut pixels = Vec::with_capacity((w * h) as usize);
    for (row, s) in rows {
        specular += s;
        pixels.extend(row);
    }
    Ok(Rendered {
        image: Image {
            width: w,
            height: h,
            pixels,
        },
        specular,
    })
}

fn luminance(p: &[f32; 3]) -> f32 {
    0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]
}

/// The automatic exposure, in stops: the 95th percentile of the lit pixels' luminance is put at
/// 0.85 of full scale, so surfaces keep their shading and only the brightest few per cent (the
/// lights) clip.
pub fn auto_exposure(img: &Image) -> f64 {
    let mut lum: Vec<f32> = img
        .pixels
        .iter()
        .map(luminance)
        .filter(|l| *l > 0.0)
        .collect();
    if lum.is_empty() {
        return 0.0;
    }
    lum.sort_by(f32::total_cmp);
    let p95 = lum[((lum.len() - 1) as f64 * 0.95) as usize] as f64;
    (0.85 / p95).log2()
}

fn srgb(x: f64) -> u8 {
    let x = x.clamp(0.0, 1.0);
    let v = if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    };
    (v * 255.0 + 0.5) as u8
}

/// Writes an 8-bit sRGB PNG: radiance × 2^exposure, clipped, sRGB-encoded.
pub fn write_png(img: &Image, exposure: f64, path: &Path) -> Result<()> {
    let scale = 2f64.powf(exposure);
    let data: Vec<u8> = img
        .pixels
        .iter()
        .flat_map(|p| {
            [
                srgb(p[0] as f64 * scale),
                srgb(p[1] as f64 * scale),
                srgb(p[2] as f64 * scale),
            ]
        })
        .collect();
    let file =
        std::fs::File::create(path).with_context(|| format!("cannot create {}", path.display()))?;
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), img.width, img.height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let mut writer = enc.write_header()?;
    writer.write_image_data(&data)?;
    writer.finish()?;
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
