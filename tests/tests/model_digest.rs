//! A digest of everything the model answers on fixed workloads (every hit's patch, t, u, v and
//! side, every rotated direction, and the clock counts), pinned to the values the model gave
//! before its simulation-speed work: a change that makes the model faster must leave every
//! result bit and every cycle count as it was.
//!
//! `cargo test --release -p hemi-tests --test model_digest -- --nocapture` prints the digests.
//! If the model's behaviour is changed on purpose, update the pinned values in the same commit
//! and say why.

use hemi_hdl_model::{ModelAccelerator, ModelConfig};
use hemi_kernel::accel::{Accelerator, Hit, Ray};
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::{DeltaRule, OwnedHemisphere};
use hemi_kernel::rotation::{spin_for_sample, Rotation};

/// FNV-1a over 32-bit words.
struct Digest(u64);
impl Digest {
    fn new() -> Self {
        Digest(0xcbf2_9ce4_8422_2325)
    }
    fn word(&mut self, w: u32) {
        for b in w.to_le_bytes() {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }
    fn hit(&mut self, h: Option<Hit>) {
        match h {
            None => self.word(0xFFFF_FFFF),
            Some(h) => {
                self.word(h.patch);
                self.word(h.t.to_bits());
                self.word(h.u.to_bits());
                self.word(h.v.to_bits());
                self.word(h.front as u32);
            }
        }
    }
}

fn run(scene: &str, circles: u32, cfg: ModelConfig, every: usize) -> (u64, u64) {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let scene = hemi::scene::load(&root.join(scene)).unwrap();
    let patches = scene.kernel_patches();
    let hemi = OwnedHemisphere::new(circles, DeltaRule::Band).unwrap();
    let view = hemi.view();
    let mut model = Box::new(ModelAccelerator::new(&patches, cfg).unwrap());
    let mut d = Digest::new();
    let points: Vec<_> = (0..patches.len())
        .flat_map(|i| {
            hemi::pass1::sample_points(&scene, i, 2)
                .into_iter()
                .map(move |p| (i, p))
        })
        .collect();
    for (q, (i, p)) in points.iter().enumerate().step_by(every) {
        let rot = Rotation::onto_spun(p.normal, spin_for_sample(q as u32));
        model.set_origin_patch((q % 2 == 0).then_some(*i as u32));
        model.cast_rings(
            p.position,
            &rot,
            &view,
            0..view.rings().len(),
            true,
            |j, k, h| {
                d.word(j as u32);
                d.word(k);
                d.hit(h);
            },
        );
        let r = model.rotate(&rot, Vec3::new(0.6, 0.0, 0.8));
        for c in [r.x, r.y, r.z] {
            d.word(c.to_bits());
        }
        // a single ray from outside the scene's box, towards the sample point
        let o = p.position + p.normal * 3.0;
        let h = model.nearest_hit(
            &Ray {
                origin: o,
                dir: -p.normal,
            },
            f32::INFINITY,
        );
        d.hit(h);
    }
    d.word(model.cycles() as u32);
    d.word((model.cycles() >> 32) as u32);
    (d.0, model.cycles())
}

#[test]
fn cornell_box_answers_and_clocks_are_pinned() {
    let got = run("scenes/cornell.toml", 12, ModelConfig::default(), 3);
    println!("cornell default: {got:#x?}");
    let narrow = ModelConfig {
        iterations: 12,
        width: 16,
        depth: 7,
        ..ModelConfig::default()
    };
    let got_narrow = run("scenes/cornell.toml", 8, narrow, 5);
    println!("cornell narrow: {got_narrow:#x?}");
    assert_eq!(got, PINNED_CORNELL);
    assert_eq!(got_narrow, PINNED_CORNELL_NARROW);
}

#[test]
fn teapot_answers_and_clocks_are_pinned() {
    let got = run("scenes/teapot.toml", 4, ModelConfig::default(), 9);
    println!("teapot default: {got:#x?}");
    let narrow = ModelConfig {
        subdivision_depth: 6,
        coord_width: 14,
        flatness: 0.0,
        ..ModelConfig::default()
    };
    let got_narrow = run("scenes/teapot.toml", 4, narrow, 23);
    println!("teapot narrow: {got_narrow:#x?}");
    assert_eq!(got, PINNED_TEAPOT);
    assert_eq!(got_narrow, PINNED_TEAPOT_NARROW);
}

const PINNED_CORNELL: (u64, u64) = (0xe836_1aeb_906e_ce72, 0x2fb67);
const PINNED_CORNELL_NARROW: (u64, u64) = (0x3d68_c8cb_86e1_0883, 0xc9c7);
const PINNED_TEAPOT: (u64, u64) = (0xbce6_1985_34a1_d2f0, 0x37e0f);
const PINNED_TEAPOT_NARROW: (u64, u64) = (0x9760_d350_5754_7094, 0x13f11);
