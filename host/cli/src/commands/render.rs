//! `hemi render`: both passes, then the image files.

use crate::options::{FieldArgs, SolverArgs, ViewArgs};
use crate::output::{ImageFormat, ImageTarget};
use crate::pipeline::{RunArgs, Solved};
use crate::progress::bar;
use anyhow::Result;
use clap::Args;
use hemi::backend::SoftEngine;
use hemi::render::{Image, Rendered};
use hemi_kernel::camera::Camera;
use hemi_kernel::specular::SpecularStats;
use std::io::Write;
use std::path::PathBuf;

/// Both passes: writes the image (8-bit sRGB PNG, linear EXR or Radiance HDR, by extension).
#[derive(Args)]
pub struct RenderArgs {
    #[command(flatten)]
    run: RunArgs,
    /// The image, its format by extension: .png (8-bit sRGB at the exposure), .exr (linear
    /// OpenEXR), .hdr or .pic (linear Radiance RGBE), or - for PNG on stdout. Checked before
    /// pass 1.
    #[arg(short, long, value_name = "OUT")]
    output: PathBuf,
    /// Also write the linear radiances as OpenEXR to this file (not the -o file).
    #[arg(long, value_name = "OUT.exr")]
    exr: Option<PathBuf>,
    #[command(flatten)]
    view: ViewArgs,
    /// Eye rays per pixel (anti-aliasing).
    #[arg(long, default_value_t = 1)]
    spp: u32,
    /// Exposure in stops applied before the PNG's sRGB encoding (default: automatic).
    #[arg(long, allow_hyphen_values = true)]
    exposure: Option<f64>,
    /// Draw the sample points adaptive sampling shot over the image, coloured by level
    /// (white: initial guess, then yellow, orange, red, magenta, blue); needs --adaptive.
    #[arg(long)]
    show_samples: bool,
    /// Memory the picture may take, in MiB (about 24 bytes a pixel: the image, each row's hits
    /// and the file's buffer); checked before pass 1.
    #[arg(long, default_value_t = 4096, value_name = "MIB")]
    image_mib: u64,
    #[command(flatten)]
    solver: SolverArgs,
    #[command(flatten)]
    field: FieldArgs,
}

/// Runs `hemi render`, writing the image to `out` for `-o -`.
pub fn run(args: RenderArgs, out: &mut impl Write) -> Result<()> {
    anyhow::ensure!(
        (1..=4096).contains(&args.spp),
        "--spp {}: must be between 1 and 4096",
        args.spp
    );
    if let Some(ev) = args.exposure {
        anyhow::ensure!(
            ev.abs() <= MAX_STOPS,
            "--exposure {ev}: must be a number of stops between -{MAX_STOPS} and {MAX_STOPS} \
             (2^{MAX_STOPS} already takes any radiosity f32 holds to white or black)"
        );
    }
    anyhow::ensure!(
        !args.show_samples || args.run.adaptive.on(),
        "--show-samples draws the points of adaptive sampling: add --adaptive"
    );
    let target = ImageTarget::of(&args.output, args.exr.as_deref())?;
    if let ImageTarget::File(path, _) = &target {
        crate::output::not_the_input(path, "-o", &args.run.scene)?;
    }
    if let Some(exr) = &args.exr {
        crate::output::export_path(exr, "--exr", &["exr"])?;
        crate::output::not_the_input(exr, "--exr", &args.run.scene)?;
    }
    if let (Some(ev), ImageTarget::File(path, ImageFormat::Exr | ImageFormat::Hdr)) =
        (args.exposure, &target)
    {
        eprintln!(
            "warning: --exposure {ev} does not change {}: .exr and .hdr hold linear radiance; \
             only PNG output is exposed",
            path.display()
        );
    }
    let field = args.field.settings()?;
    let run = args.run.prepare(|scene| {
        scene.camera = Some(args.view.camera(scene.camera.as_ref())?);
        let camera = hemi::render::camera_of(scene)?;
        check_image(&camera, args.image_mib)
    })?;
    let (scene, settings) = (&run.scene, &run.settings);
    let camera = hemi::render::camera_of(scene)?;
    let backend = run.engine.backend(scene, settings)?;
    let stats = args.run.engine.boards.board_stats;
    let solved = args.run.solve(&backend, &args.solver, Some(field))?;
    let pass1_counts = backend.model_counts();
    let t2 = std::time::Instant::now();
    let bar = bar(u64::from(camera.height), "pass 2");
    let light = hemi::irradiance::Light {
        grids: &solved.grids,
        direct: solved.direct.as_ref(),
    };
    let Rendered { image, specular } =
        hemi::render::render(backend.get(), light, &camera, args.spp, &|n| bar.inc(n))?;
    bar.finish_and_clear();
    backend.board_report(stats, "after pass 2");
    let pass2 = t2.elapsed().as_secs_f64();
    let ev = write_images(&args, &target, out, scene, &camera, &solved, image)?;
    eprintln!(
        "pass 1 {:.3} s ({} rays), solve {:.3} s ({}, {} sweeps), pass 2 {pass2:.3} s ({}x{}, {} \
         spp), exposure {ev:+.2} EV -> {}",
        solved.seconds.0,
        solved.stats.rays,
        solved.seconds.1,
        solved.solution.solver.name(),
        solved.solution.iterations,
        camera.width,
        camera.height,
        args.spp,
        args.output.display()
    );
    report_specular(settings, &solved, &specular, &camera, args.spp);
    let clock = args.run.engine.model.clock_mhz;
    backend.report_model(solved.hemispheres, clock, "pass 1 and pass 2");
    if let (Some((c, r)), Some((c1, r1))) = (backend.model_counts(), pass1_counts) {
        eprintln!(
            "model: pass 1 {c1} cycles ({:.0} per hemisphere), pass 2 {} cycles for {} rays",
            c1 as f64 / solved.hemispheres.max(1) as f64,
            c - c1,
            r - r1
        );
    }
    Ok(())
}

/// The largest `--exposure`, in stops either way.
const MAX_STOPS: f64 = 128.0;

/// The exposure (given or automatic), the sample overlay of `--show-samples`, and the image
/// files (or the PNG on `out`); returns the exposure.
fn write_images(
    args: &RenderArgs,
    target: &ImageTarget,
    out: &mut impl Write,
    scene: &hemi::scene::Scene,
    camera: &Camera,
    solved: &Solved,
    mut img: Image,
) -> Result<f64> {
    let ev = args
        .exposure
        .unwrap_or_else(|| hemi::render::auto_exposure(&img));
    warn_if_black(scene, &img);
    if args.show_samples {
        let radius = (camera.height as f32 / 400.0).max(1.0);
        let patches = scene.kernel_patches();
        let mut engine = SoftEngine::new(&patches);
        let dots =
            hemi::overlay::draw_samples(&mut img, camera, &solved.sampled, &mut engine, ev, radius);
        eprintln!("--show-samples: {dots} visible sample points drawn");
    }
    match target {
        ImageTarget::Stdout => hemi::render::write_png_to(&img, ev, out)?,
        ImageTarget::File(path, ImageFormat::Png) => hemi::render::write_png(&img, ev, path)?,
        ImageTarget::File(path, ImageFormat::Exr) => hemi::render::write_exr(&img, path)?,
        ImageTarget::File(path, ImageFormat::Hdr) => hemi::render::write_hdr(&img, path)?,
    }
    if let Some(exr) = &args.exr {
        hemi::render::write_exr(&img, exr)?;
    }
    Ok(ev)
}

/// Bytes a pixel of pass 2 takes: 21 were measured at 8192 × 8192 (1.39 GB peak).
const PIXEL_BYTES: u64 = 24;

/// Refuses a picture whose memory would pass `image_mib` (`--image-mib`), before any pass.
fn check_image(camera: &Camera, image_mib: u64) -> Result<()> {
    let pixels = u64::from(camera.width) * u64::from(camera.height);
    let bytes = pixels.saturating_mul(PIXEL_BYTES);
    anyhow::ensure!(
        bytes <= image_mib.saturating_mul(1 << 20),
        "render: a {}×{} picture needs about {} MiB ({PIXEL_BYTES} bytes a pixel), more than \
         --image-mib {image_mib} (a smaller --size, or a larger --image-mib)",
        camera.width,
        camera.height,
        bytes >> 20
    );
    Ok(())
}

/// A warning when every pixel of a lit scene is black: the picture would say nothing of why (a
/// scene where nothing emits was warned about before pass 1).
fn warn_if_black(scene: &hemi::scene::Scene, img: &Image) {
    let black = img.pixels.iter().all(|p| p.iter().all(|c| *c == 0.0));
    if black && scene.emits() {
        eprintln!(
            "warning: the image is black: no lit surface is in view (check --eye, --look-at and \
             --fov, or the camera in the scene)"
        );
    }
}

/// What the frustums of both passes did, on stderr, when there were any.
fn report_specular(
    settings: &hemi::settings::Pass1Settings,
    solved: &Solved,
    pass2: &SpecularStats,
    camera: &Camera,
    spp: u32,
) {
    if solved.stats.specular.frustums + pass2.frustums == 0 {
        return;
    }
    let describe = hemi::optics::describe;
    let rays = solved.stats.rays;
    eprintln!(
        "{}",
        describe(
            "specular, pass 1",
            &solved.stats.specular,
            rays,
            &settings.specular
        )
    );
    let eye_rays = u64::from(camera.width) * u64::from(camera.height) * u64::from(spp);
    eprintln!(
        "{}",
        describe("specular, pass 2", pass2, eye_rays, &settings.specular)
    );
}
