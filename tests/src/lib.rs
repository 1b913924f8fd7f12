//! Shared helpers for hemi's integration tests: Howell's closed-form form factors (the reference
//! values the accuracy tests compare against) and small scene builders.

pub use hemi::analytic::*;

/// TOML for one quad patch.
pub fn quad(name: &str, material: &str, v: [[f64; 3]; 4]) -> String {
    let vs: Vec<String> = v
        .iter()
        .map(|p| format!("[{}, {}, {}]", p[0], p[1], p[2]))
        .collect();
    format!(
        "[[quad]]\nname = \"{name}\"\nmaterial = \"{material}\"\nvertices = [{}]\n\n",
        vs.join(", ")
    )
}

/// Pass 1 on the soft backend at R = `circles` and K = `samples`, the other settings default.
pub fn form_factors_at(
    scene: &hemi::scene::Scene,
    circles: u32,
    samples: u32,
) -> hemi::pass1::FormFactors {
    let settings = hemi::settings::Pass1Settings {
        circles,
        samples,
        ..Default::default()
    };
    hemi::pass1::form_factors(&hemi::backend::soft(scene, &settings).unwrap(), &|_| {}).unwrap()
}

/// TOML for one material.
pub fn material(name: &str, diffuse: f64, emission: f64) -> String {
    format!(
        "[[material]]\nname = \"{name}\"\ndiffuse = [{diffuse}, {diffuse}, {diffuse}]\nemission = [{emission}, {emission}, {emission}]\n\n"
    )
}

/// A closed axis-aligned box `[0,sx]×[0,sy]×[0,sz]` with inward-facing walls, each wall cut into
/// n × n quads that share their vertices exactly.
pub fn closed_box(size: [f64; 3], n: usize, material: &str) -> String {
    let mut out = String::new();
    // (axis fixed, value, inward sign), two in-plane axes chosen so that the normal points inward
    let faces = [
        (0usize, 0.0, 1.0),
        (0, size[0], -1.0),
        (1, 0.0, 1.0),
        (1, size[1], -1.0),
        (2, 0.0, 1.0),
        (2, size[2], -1.0),
    ];
    for (f, &(axis, value, sign)) in faces.iter().enumerate() {
        let (a1, a2) = ((axis + 1) % 3, (axis + 2) % 3);
        for i in 0..n {
            for j in 0..n {
                let corner = |di: usize, dj: usize| {
                    let mut p = [0.0; 3];
                    p[axis] = value;
                    p[a1] = size[a1] * (i + di) as f64 / n as f64;
                    p[a2] = size[a2] * (j + dj) as f64 / n as f64;
                    p
                };
                // (a1 × a2) = +axis: counter-clockwise about +axis is (0,0),(1,0),(1,1),(0,1)
                let v = if sign > 0.0 {
                    [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)]
                } else {
                    [corner(0, 0), corner(0, 1), corner(1, 1), corner(1, 0)]
                };
                out += &quad(&format!("f{f}_{i}_{j}"), material, v);
            }
        }
    }
    out
}

// --- Hardware-in-the-loop helpers ---

/// Whether a HIL test can run: true when qemu-system-arm is runnable. Otherwise the test is
/// skipped with a message, unless `HEMI_REQUIRE_QEMU` is set (as `cargo xtask test` does), which
/// turns the skip into a failure so that CI cannot pass by skipping.
pub fn qemu_or_skip(test: &str) -> bool {
    if hemi_boards::qemu_available() {
        return true;
    }
    let required = std::env::var("HEMI_REQUIRE_QEMU").is_ok_and(|v| !v.is_empty() && v != "0");
    assert!(
        !required,
        "HEMI_REQUIRE_QEMU is set but qemu-system-arm is not runnable \
         (install it: apt-get install -y qemu-system-arm)"
    );
    eprintln!(
        "SKIPPED {test}: qemu-system-arm not found (apt-get install -y qemu-system-arm; \
         HEMI_REQUIRE_QEMU=1 turns this skip into a failure)"
    );
    false
}

/// The Cornell box of `scenes/cornell.toml`.
pub fn cornell_scene() -> hemi::scene::Scene {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    hemi::scene::load(&root.join("scenes/cornell.toml")).expect("cornell scene")
}

/// Runs `f` where the in-process model fits the stack: a debug build keeps the model (~140 KiB)
/// on the stack several times over, more than rayon's default 2 MiB worker stacks.
pub fn big_stack(f: impl FnOnce() + Send + 'static) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .stack_size(256 << 20)
        .build()
        .unwrap();
    std::thread::Builder::new()
        .stack_size(256 << 20)
        .spawn(move || pool.install(f))
        .unwrap()
        .join()
        .unwrap();
}
