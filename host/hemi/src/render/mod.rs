//! Pass 2: eye rays through every pixel by the backend's pixel tracer, diffuse colour from the
//! hit patch's vertex grid at the hit's (u,v) ([`shade`]) — with the lamps' light exact on the
//! shadows' edges the grid cannot carry ([`relit`]) — then exposure, tone map and the image
//! files: PNG and EXR ([`image`]), Radiance's RGBE ([`hdr`]).

pub mod hdr;
pub mod image;
pub mod relit;

pub use hdr::write_hdr;
pub use image::{auto_exposure, read_png, write_exr, write_png, write_png_to, Image};

use crate::backend::{Backend, Progress, Seen};
use crate::direct::{applies, Emitters};
use crate::irradiance::Light;
use crate::radiosity::{grid_of, Grid};
use crate::scene::Scene;
use anyhow::{Context, Result};
use hemi_kernel::camera::Camera;
use hemi_kernel::specular::SpecularStats;
use std::sync::Mutex;

/// The kernel camera of a scene's `[camera]`.
pub fn camera_of(scene: &Scene) -> Result<Camera> {
    let c = scene
        .camera
        .as_ref()
        .context("the scene has no [camera] table: pass 2 needs one (docs/scene-format.md)")?;
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
/// reached, times the weight the specular path passed on.
pub fn shade(px: &mut [f32; 3], weight: [f32; 3], b: [f64; 3], spp: u32) {
    for c in 0..3 {
        px[c] += (weight[c] as f64 * b[c] / std::f64::consts::PI / spp as f64) as f32;
    }
}

/// Renders the backend's scene through `camera` with `spp` eye rays per pixel. A ray on a
/// diffuse patch's front side sees its radiance B(u,v)/π (emitters included, so a light shows
/// its radiance); a ray on a specular patch adds what its frustums see, weighted by k and the
/// lobe (§5); back sides and misses are black. Frustums are cut from the backend's hemisphere
/// and bounded by its specular settings, as in pass 1. Where `light` has the field's reflected
/// direct light and exact direct light applies, the hits on shadows' edges are relit
/// ([`relit`]). `progress` gets the rows finished.
pub fn render(
    backend: &dyn Backend,
    light: Light<'_>,
    camera: &Camera,
    spp: u32,
    progress: &Progress<'_>,
) -> Result<Rendered> {
    let (w, h) = (camera.width, camera.height);
    let spp = spp.max(1);
    let grids = light.grids;
    let rows: Vec<Mutex<Vec<[f32; 3]>>> = (0..h)
        .map(|_| Mutex::new(vec![[0.0f32; 3]; w as usize]))
        .collect();
    let failed: Mutex<Option<anyhow::Error>> = Mutex::new(None);
    // the shadows' edges are relit after the trace ([`relit`]), where exact direct light applies
    let emitters = light
        .direct
        .filter(|_| applies(backend))
        .map(|d| (d, Emitters::of(backend.scene())));
    let to_relight: Mutex<Vec<relit::Hit>> = Mutex::new(Vec::new());
    let sink = |y: u32, seen: &[(u32, Seen)]| {
        let shaded = shade_row(&rows, grids, y, w, seen, spp);
        if let (Ok(()), Some((direct, em))) = (&shaded, &emitters) {
            let mine = seen.iter().enumerate().filter_map(|(n, (p, s))| {
                relit::wants(grids, direct, em, s).then_some((*p, n as u32, *s))
            });
            if let Ok(mut all) = to_relight.lock() {
                all.extend(mine);
            }
        }
        if let Err(e) = shaded {
            if let Ok(mut f) = failed.lock() {
                f.get_or_insert(e);
            }
        }
    };
    let specular = backend.trace(camera, spp, 0..h, &sink, progress)?;
    if let Some(e) = failed.into_inner().ok().flatten() {
        return Err(e);
    }
    let mut pixels = Vec::with_capacity(w as usize * h as usize);
    for row in rows {
        pixels.extend(
            row.into_inner()
                .map_err(|_| anyhow::anyhow!("a row was poisoned"))?,
        );
    }
    if let Some((direct, em)) = &emitters {
        let mut hits = to_relight
            .into_inner()
            .map_err(|_| anyhow::anyhow!("the relit hits were poisoned"))?;
        // rows arrive in any order: the pixels' sums must not depend on it
        hits.sort_by_key(|&(p, n, _)| (p, n));
        let add = relit::corrections(backend, em, grids, direct, &hits)?;
        for ((p, _, s), d) in hits.iter().zip(add) {
            if let Some(px) = pixels.get_mut(*p as usize) {
                shade(px, s.weight, d, spp);
            }
        }
    }
    let image = Image {
        width: w,
        height: h,
        pixels,
    };
    Ok(Rendered { image, specular })
}

/// Shades what the eye rays of image row `y` saw into it, report by report in tracer order.
fn shade_row(
    rows: &[Mutex<Vec<[f32; 3]>>],
    grids: &[Grid],
    y: u32,
    w: u32,
    seen: &[(u32, Seen)],
    spp: u32,
) -> Result<()> {
    let mut row = rows
        .get(y as usize)
        .context("a backend reported a row outside the image")?
        .lock()
        .map_err(|_| anyhow::anyhow!("a row was poisoned"))?;
    for (p, s) in seen {
        let x = p.checked_sub(y * w).filter(|x| *x < w);
        let px = x
            .and_then(|x| row.get_mut(x as usize))
            .context("a backend reported a ray outside its row")?;
        shade(px, s.weight, grid_of(grids, s.side)?.at(s.u, s.v), spp);
    }
    Ok(())
}
