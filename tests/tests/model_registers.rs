//! Register-level behaviour of the accelerator model, through the bus the driver uses:
//! handshakes, FIFO overflow and underflow, reset mid-job, refused configurations, interrupts.

use hemi_hdl_model::cordic::CordicConfig;
use hemi_hdl_model::device::{Device, BZ_CONFIG_RESET, CONFIG_RESET, RAY_FIFO_DEPTH};
use hemi_hdl_model::driver::{Driver, ModelBus, RegisterAccess};
use hemi_hdl_model::format::Unit;
use hemi_hdl_model::intersect::bezier::{BEZIER_ROWS, CP_WORDS, LEAF_CLOCKS, STACK_ENTRIES};
use hemi_hdl_model::intersect::patch_mem::{BezierSlot, CP_BASE};
use hemi_hdl_model::regs::{self, config, ctrl, error, irq, mode, result, status};
use hemi_hdl_model::Params;

fn w(x: f32) -> u32 {
    Unit::from_num(x).to_bits() as u32
}

fn bus() -> ModelBus {
    let mut b = ModelBus::new();
    b.write(regs::CTRL, ctrl::ENABLE);
    b
}

#[test]
fn identifies_itself_and_resets_to_documented_values() {
    let mut b = ModelBus::new();
    assert_eq!(b.read(regs::ID), regs::ID_VALUE);
    assert_eq!(b.read(regs::VERSION), regs::VERSION_VALUE);
    assert_eq!(b.read(regs::CONFIG), CONFIG_RESET);
    assert_eq!(b.read(regs::CONFIG_ACTIVE), CONFIG_RESET);
    assert_eq!(b.read(regs::CTRL), 0);
    assert_eq!(b.read(regs::ERROR), 0);
    assert_eq!(b.read(regs::STATUS), 0);
    assert_eq!(b.read(regs::CAPS) & 0xFF, RAY_FIFO_DEPTH as u32);
}

/// The kernel names the reset CORDIC configuration for the link (it cannot name the model's):
/// the two must agree, or a soft engine would refuse what a host asks by default.
#[test]
fn the_kernels_reset_cordic_is_the_models() {
    let d = CordicConfig::DEFAULT;
    assert_eq!(
        hemi_kernel::link::RESET_CORDIC,
        (d.iterations as u8, d.width as u8)
    );
    assert_eq!(CONFIG_RESET & 0x1F, d.iterations);
}

#[test]
fn start_bits_self_clear_and_busy_ready_handshake() {
    let mut b = bus();
    b.write(regs::PHI_C, w(0.5f32.cos()));
    b.write(regs::PHI_S, w(0.5f32.sin()));
    b.write(regs::THETA_C, w(1.0));
    b.write(regs::THETA_S, 0);
    b.write(regs::SPIN_C, w(1.0 - 1e-9));
    b.write(regs::SPIN_S, 0);
    b.write(regs::CTRL, ctrl::ENABLE | ctrl::FRAME_PAIRS);
    // the command bit reads back clear at once; the angle unit is busy
    assert_eq!(b.read(regs::CTRL), ctrl::ENABLE);
    assert_ne!(b.read(regs::STATUS) & status::FRAME_BUSY, 0);
    let mut clocks = 0;
    while b.read(regs::STATUS) & status::BUSY != 0 {
        clocks += 1;
        assert!(clocks < 1000);
    }
    let s = b.read(regs::STATUS);
    assert_ne!(s & status::FRAME_VALID, 0);
    assert_eq!(s & status::RESULT_READY, 0);
    // one rotation: RESULT_READY rises only after the rotator's latency
    b.write(regs::MODE, mode::ROTATE);
    for c in [1.0, 0.0, 0.0] {
        b.write(regs::RAY_IN, w(c));
    }
    assert_ne!(b.read(regs::STATUS) & status::BUSY, 0);
    let mut waited = 0;
    while b.read(regs::STATUS) & status::RESULT_READY == 0 {
        waited += 1;
        assert!(waited < 1000);
    }
    assert!(
        waited > 3 * 24,
        "result after {waited} clocks: not pipelined as specified"
    );
    let r: [u32; 4] = core::array::from_fn(|_| b.read(regs::RESULT_OUT));
    assert_eq!(r[0], result::ROTATED);
    let x = Unit::from_bits(r[1] as i32).to_num::<f32>();
    let y = Unit::from_bits(r[2] as i32).to_num::<f32>();
    let tol = CordicConfig::DEFAULT.turn_bound() as f32;
    assert!((x - 0.5f32.cos()).abs() < tol && (y - 0.5f32.sin()).abs() < tol);
    assert_eq!(
        b.read(regs::STATUS) & (status::BUSY | status::RESULT_READY),
        0
    );
}

#[test]
fn fifo_overflow_and_underflow_are_reported() {
    let mut b = ModelBus::new(); // ENABLE clear: entries wait in the FIFO
    b.write(regs::MODE, mode::TRACE);
    for _ in 0..RAY_FIFO_DEPTH {
        for c in [0.0, 0.0, 1.0] {
            b.write(regs::RAY_IN, w(c));
        }
    }
    let s = b.read(regs::STATUS);
    assert_ne!(s & status::RAY_FULL, 0);
    assert_eq!((s >> status::RAY_LEVEL_SHIFT) & 0xFF, RAY_FIFO_DEPTH as u32);
    assert_eq!(b.read(regs::ERROR), 0);
    for c in [0.0, 0.0, 1.0] {
        b.write(regs::RAY_IN, w(c));
    }
    assert_eq!(b.read(regs::ERROR), error::RAY_OVERFLOW);
    assert_ne!(b.read(regs::IRQ_STATUS) & irq::ERROR, 0);
    // write 1 to clear
    b.write(regs::ERROR, error::RAY_OVERFLOW);
    assert_eq!(b.read(regs::ERROR), 0);
    // underflow: nothing to read
    assert_eq!(b.read(regs::RESULT_OUT), 0);
    assert_eq!(b.read(regs::ERROR), error::RESULT_UNDERFLOW);
    // enabling drains the FIFO: 32 misses (no patches loaded)
    b.write(regs::CTRL, ctrl::ENABLE);
    let mut n = 0;
    for _ in 0..10_000 {
        if b.read(regs::STATUS) & status::RESULT_READY != 0 {
            let r: [u32; 4] = core::array::from_fn(|_| b.read(regs::RESULT_OUT));
            assert_eq!(r, [0; 4]);
            n += 1;
        }
    }
    assert_eq!(n, RAY_FIFO_DEPTH);
}

#[test]
fn soft_reset_mid_job_leaves_a_working_idle_device() {
    let mut b = bus();
    b.write(regs::IRQ_ENABLE, irq::RESULT);
    b.write(regs::MODE, mode::ROTATE); // no frame yet: would raise NO_FRAME
    for c in [1.0, 0.0, 0.0] {
        b.write(regs::RAY_IN, w(c));
    }
    for _ in 0..10 {
        b.read(regs::STATUS);
    }
    assert_ne!(b.read(regs::STATUS) & status::BUSY, 0);
    b.write(regs::CTRL, ctrl::SOFT_RESET);
    assert_eq!(b.read(regs::CTRL), 0, "reset clears ENABLE and self-clears");
    assert_eq!(b.read(regs::STATUS), 0);
    assert_eq!(b.read(regs::ERROR), 0);
    assert_eq!(b.read(regs::IRQ_STATUS), 0);
    assert!(b.read(regs::CYCLE_LO) < 10, "cycle counter restarts");
    for _ in 0..200 {
        assert_eq!(
            b.read(regs::STATUS) & status::RESULT_READY,
            0,
            "no stale result"
        );
    }
    // and it works afterwards, through the driver
    let mut d = Driver::new(b).unwrap();
    d.frame_from_pairs([w(1.0 - 1e-9), 0], [w(1.0 - 1e-9), 0], [w(1.0 - 1e-9), 0]);
    d.set_mode(mode::ROTATE);
    let mut got = [0; 4];
    d.stream(1, |_| [0, 0, w(1.0)], |_, r| got = r).unwrap();
    assert_eq!(got[0], result::ROTATED);
    assert!(d.bus().device().irq_line() || d.bus_mut().read(regs::IRQ_STATUS) & irq::RESULT != 0);
}

#[test]
fn bad_configuration_is_refused() {
    let mut d = Driver::new(ModelBus::new()).unwrap();
    // iterations beyond the fraction bits, width too small, depth 0, iterations too many
    for (n, width, depth) in [
        (20, 16, 16),
        (8, 8, 16),
        (16, 24, 0),
        (31, 32, 16),
        (3, 32, 8),
    ] {
        assert!(d.configure(n, width, depth).is_err(), "{n} {width} {depth}");
        assert_eq!(d.bus_mut().read(regs::CONFIG_ACTIVE), CONFIG_RESET);
    }
    assert!(d.configure(12, 16, 8).is_ok());
    // refused while busy
    d.bus_mut().write(regs::CTRL, 0); // disable: the entry stays queued, BUSY stays set
    d.set_mode(mode::TRACE);
    d.push_ray([0, 0, w(1.0)]);
    assert!(matches!(
        d.configure(16, 20, 8),
        Err(hemi_hdl_model::DriverError::BadConfig(e)) if e & error::CONFIG_BUSY != 0
    ));
    // a bad MODE value is refused too
    let b = d.bus_mut();
    b.write(regs::MODE, 3);
    assert_ne!(b.read(regs::ERROR) & error::BAD_CONFIG, 0);
    assert_eq!(b.read(regs::MODE), mode::TRACE);
}

#[test]
fn a_build_synthesised_for_one_configuration_refuses_another() {
    // 12 iterations on 16-bit words, 8 (u,v) levels: in force from power-on
    let built = 12 | 16 << config::WIDTH_SHIFT | 8 << config::DEPTH_SHIFT;
    let dev = Device::with_params(Params::SINGLE).built_for(built);
    let mut b = ModelBus::with_device(dev);
    assert_eq!(b.read(regs::CONFIG_ACTIVE), built);
    let refused = |b: &mut ModelBus| {
        b.write(regs::ERROR, u32::MAX);
        b.write(regs::CONFIG, CONFIG_RESET);
        b.write(regs::CTRL, ctrl::APPLY_CONFIG);
        b.read(regs::ERROR) & error::BAD_CONFIG != 0 && b.read(regs::CONFIG_ACTIVE) == built
    };
    assert!(
        refused(&mut b),
        "a valid CONFIG the units were not built for"
    );
    // its own is taken; and a soft reset keeps the build's configuration and its refusal
    b.write(regs::ERROR, u32::MAX);
    b.write(regs::CONFIG, built);
    b.write(regs::CTRL, ctrl::APPLY_CONFIG);
    assert_eq!(b.read(regs::ERROR), 0);
    b.write(regs::CTRL, ctrl::SOFT_RESET);
    assert_eq!(b.read(regs::CONFIG_ACTIVE), built);
    assert!(refused(&mut b), "after a soft reset");
}

#[test]
fn patch_memory_window_bounds_and_cycle_counter() {
    let mut b = bus();
    let cap = b.read(regs::CAPS) >> 16;
    b.write(regs::PATCH_ADDR, cap * 16 - 1);
    b.write(regs::PATCH_DATA, 7);
    assert_eq!(b.read(regs::ERROR), 0);
    b.write(regs::PATCH_DATA, 7); // one past the end
    assert_eq!(b.read(regs::ERROR), error::PATCH_RANGE);
    b.write(regs::ERROR, u32::MAX);
    b.write(regs::PATCH_COUNT, cap + 1);
    assert_eq!(b.read(regs::ERROR), error::PATCH_RANGE);
    // an unknown kind is reported when scanned
    b.write(regs::ERROR, u32::MAX);
    b.write(regs::PATCH_ADDR, 0);
    b.write(regs::PATCH_DATA, 4);
    b.write(regs::PATCH_COUNT, 1);
    b.write(regs::MODE, mode::TRACE);
    for c in [0.0, 0.0, 1.0] {
        b.write(regs::RAY_IN, w(c));
    }
    for _ in 0..200 {
        b.read(regs::STATUS);
    }
    assert_ne!(b.read(regs::ERROR) & error::UNSUPPORTED_PATCH, 0);
    let lo = b.read(regs::CYCLE_LO);
    let lo2 = b.read(regs::CYCLE_LO);
    assert_eq!(lo2, lo + 1, "one clock per bus access");
    assert_eq!(b.read(regs::CYCLE_HI), 0);
}

#[test]
fn bezier_capabilities_and_configuration_refused_beyond_the_stack() {
    let mut d = Driver::new(ModelBus::new()).unwrap();
    let b = d.bus_mut();
    assert_eq!(b.read(regs::BZ_CONFIG_ACTIVE), BZ_CONFIG_RESET);
    let caps = b.read(regs::CAPS_BEZIER);
    assert_eq!(caps & 0xFFFF, BEZIER_ROWS as u32);
    assert_eq!((caps >> 16) & 0xFF, STACK_ENTRIES as u32);
    assert_eq!(caps >> 24, 16);
    // depth 14 needs 3·14 = 42 stack entries for its worst case: more than the 40 on chip
    for (depth, width) in [(14, 26), (16, 26), (0, 26), (10, 27), (10, 11)] {
        assert!(
            d.configure_subdivision(depth, width).is_err(),
            "{depth} {width}"
        );
        assert_eq!(d.bus_mut().read(regs::BZ_CONFIG_ACTIVE), BZ_CONFIG_RESET);
    }
    assert!(d.configure_subdivision(13, 26).is_ok());
    assert!(d.configure_subdivision(6, 16).is_ok());
    assert_eq!(d.bus_mut().read(regs::BZ_CONFIG_ACTIVE), 6 | 16 << 8);
    // the CORDIC configuration stays as it was, and can still be changed
    assert_eq!(d.bus_mut().read(regs::CONFIG_ACTIVE), CONFIG_RESET);
    assert!(d.configure(20, 24, 12).is_ok());
    assert_eq!(d.bus_mut().read(regs::BZ_CONFIG_ACTIVE), 6 | 16 << 8);
    // refused while busy
    d.bus_mut().write(regs::CTRL, 0);
    d.set_mode(mode::TRACE);
    d.push_ray([0, 0, w(1.0)]);
    assert!(matches!(
        d.configure_subdivision(8, 20),
        Err(hemi_hdl_model::DriverError::BadConfig(e)) if e & error::CONFIG_BUSY != 0
    ));
}

/// A flat Bezier patch over [−0.5, 0.5]² at z = 0 (control points on a regular grid), its
/// control-point words.
fn flat_patch() -> [u32; CP_WORDS] {
    let mut words = [0u32; CP_WORDS];
    for r in 0..4 {
        for c in 0..4 {
            let p = [c as f32 / 3.0 - 0.5, r as f32 / 3.0 - 0.5, 0.0];
            for k in 0..3 {
                words[3 * (4 * r + c) + k] =
                    hemi_hdl_model::format::Coord::from_num(p[k]).to_bits() as u32;
            }
        }
    }
    words
}

fn trace(d: &mut Driver<ModelBus>, origin: [f32; 3], dir: [f32; 3]) -> [u32; 4] {
    let c = |x: f32| hemi_hdl_model::format::Coord::from_num(x).to_bits() as u32;
    d.set_origin(origin.map(c));
    d.set_mode(mode::TRACE);
    let mut got = [0; 4];
    d.stream(1, |_| dir.map(w), |_, r| got = r).unwrap();
    got
}

#[test]
fn bezier_patch_uploaded_through_the_window_is_traced() {
    let mut d = Driver::new(ModelBus::new()).unwrap();
    d.load_control_points([flat_patch()]).unwrap();
    d.load_patches([BezierSlot::default().encode()]).unwrap();
    // read back through the window
    let b = d.bus_mut();
    b.write(regs::PATCH_ADDR, CP_BASE + 3);
    assert_eq!(b.read(regs::PATCH_DATA), flat_patch()[3]);
    // a ray straight down onto (u, v) = (0.3, 0.8): t = 1, front side (∂P/∂u × ∂P/∂v = +z)
    let c0 = d.cycles();
    let r = trace(&mut d, [-0.2, 0.3, 1.0], [0.0, 0.0, -1.0]);
    let clocks = d.cycles() - c0;
    assert_eq!(r[0], result::HIT | result::FRONT, "{r:x?}");
    let t = hemi_hdl_model::format::Coord::from_bits(r[1] as i32).to_num::<f64>();
    let u = Unit::from_bits(r[2] as i32).to_num::<f64>();
    let v = Unit::from_bits(r[3] as i32).to_num::<f64>();
    assert!((t - 1.0).abs() < 1e-6, "t {t}");
    assert!(
        (u - 0.3).abs() < 1e-6 && (v - 0.8).abs() < 1e-6,
        "({u}, {v})"
    );
    // the subdivision costs clocks: at least 10 steps and a leaf beyond a planar scan
    assert!(clocks > 10 + LEAF_CLOCKS as u64, "{clocks} clocks");
    assert_eq!(d.take_errors(), 0);
    // a miss beside the patch, and the patch skipped by SKIP_PATCH
    assert_eq!(trace(&mut d, [0.7, 0.0, 1.0], [0.0, 0.0, -1.0])[0], 0);
    d.set_skip(Some(0));
    assert_eq!(trace(&mut d, [-0.2, 0.3, 1.0], [0.0, 0.0, -1.0])[0], 0);
    d.set_skip(None);
    assert_eq!(
        trace(&mut d, [-0.2, 0.3, 1.0], [0.0, 0.0, -1.0])[0],
        result::HIT | result::FRONT
    );
    // from below: the back side
    assert_eq!(
        trace(&mut d, [-0.2, 0.3, -1.0], [0.0, 0.0, 1.0])[0],
        result::HIT
    );
}

#[test]
fn bezier_memory_bounds_are_reported() {
    let mut d = Driver::new(ModelBus::new()).unwrap();
    // one word past the last control-point row
    let b = d.bus_mut();
    b.write(
        regs::PATCH_ADDR,
        CP_BASE + (BEZIER_ROWS * CP_WORDS) as u32 - 1,
    );
    b.write(regs::PATCH_DATA, 1);
    assert_eq!(b.read(regs::ERROR), 0);
    b.write(regs::PATCH_DATA, 1);
    assert_eq!(b.read(regs::ERROR), error::PATCH_RANGE);
    b.write(regs::ERROR, u32::MAX);
    // too many rows through the driver
    let rows = vec![flat_patch(); BEZIER_ROWS + 1];
    assert!(matches!(
        d.load_control_points(&rows),
        Err(hemi_hdl_model::DriverError::PatchMemory(e)) if e & error::PATCH_RANGE != 0
    ));
    // a slot naming a row outside the memory is skipped and reported when scanned
    let slot = BezierSlot {
        row: BEZIER_ROWS as u32,
        ..BezierSlot::default()
    };
    d.load_patches([slot.encode()]).unwrap();
    assert_eq!(trace(&mut d, [0.0, 0.0, 1.0], [0.0, 0.0, -1.0])[0], 0);
    assert_ne!(d.take_errors() & error::UNSUPPORTED_PATCH, 0);
}

/// A bus that is not the model's: what a board's MMIO access looks like to the driver (here it
/// forwards to a model, boxed, and counts the accesses).
struct ForeignBus {
    inner: Box<ModelBus>,
    accesses: u64,
}

impl RegisterAccess for ForeignBus {
    fn read(&mut self, offset: u32) -> u32 {
        self.accesses += 1;
        self.inner.read(offset)
    }
    fn write(&mut self, offset: u32, value: u32) {
        self.accesses += 1;
        self.inner.write(offset, value)
    }
}

#[test]
fn the_accelerator_runs_over_any_register_access_with_the_models_answers() {
    use hemi_hdl_model::{ModelAccelerator, ModelConfig, RegisterAccelerator};
    use hemi_kernel::accel::Accelerator;
    use hemi_kernel::hemisphere::{DeltaRule, OwnedHemisphere};
    use hemi_kernel::rotation::Rotation;
    let scene = hemi_tests::cornell_scene();
    let patches = scene.kernel_patches();
    let cfg = ModelConfig::default();
    let mut model = Box::new(ModelAccelerator::new(&patches, cfg).unwrap());
    let bus = ForeignBus {
        inner: Box::new(ModelBus::new()),
        accesses: 0,
    };
    let mut foreign = RegisterAccelerator::with_bus(bus, &patches, cfg).unwrap();
    let hemi = OwnedHemisphere::new(6, DeltaRule::Band).unwrap();
    let view = hemi.view();
    let p = hemi::shots::sample_points(&scene, 0, 2)[0];
    let rot = Rotation::onto(p.normal);
    let mut a = Vec::new();
    let mut b = Vec::new();
    let rings = 0..view.rings().len();
    model.cast_rings(p.position, &rot, &view, rings.clone(), true, |j, k, h| {
        a.push((j, k, h))
    });
    foreign.cast_rings(p.position, &rot, &view, rings, true, |j, k, h| {
        b.push((j, k, h))
    });
    assert_eq!(a, b);
    assert!(a.iter().any(|(_, _, h)| h.is_some()));
    // one clock per bus access: the counter (read before its own two accesses) says the same;
    // a bus without the stream port (a board's MMIO) moves every ray and result through the
    // register window, so it takes more clocks than the model's own bus, which has the port
    let clocks = foreign.device_cycles();
    assert!(clocks > model.cycles(), "{clocks} {}", model.cycles());
    assert_eq!(foreign.driver_mut().bus().accesses, clocks + 2);
}

#[test]
fn a_board_loads_one_scene_after_another_into_the_accelerator_it_attached_to() {
    // A board takes its registers once, at boot, with no scene (`FwAccel::attach_mmio`), and
    // loads every uploaded scene into that one accelerator: its answers must be a fresh
    // accelerator's.
    use hemi_hdl_model::{ModelAccelerator, ModelConfig, RegisterAccelerator};
    use hemi_kernel::accel::Accelerator;
    use hemi_kernel::hemisphere::{DeltaRule, OwnedHemisphere};
    use hemi_kernel::rotation::Rotation;
    let cornell = hemi_tests::cornell_scene().kernel_patches();
    let other: Vec<_> = cornell.iter().rev().take(7).copied().collect();
    let cfg = ModelConfig::default();
    let bus = ForeignBus {
        inner: Box::new(ModelBus::new()),
        accesses: 0,
    };
    let mut board = RegisterAccelerator::with_bus(bus, &[], cfg).unwrap();
    let hemi = OwnedHemisphere::new(6, DeltaRule::Band).unwrap();
    let view = hemi.view();
    for patches in [&other, &cornell, &other] {
        board.load_scene(patches, cfg).unwrap();
        let mut fresh = Box::new(ModelAccelerator::new(patches, cfg).unwrap());
        let origin = hemi_kernel::geometry::Vec3::new(278.0, 300.0, 280.0);
        let rot = Rotation::onto(hemi_kernel::geometry::Vec3::new(0.0, -1.0, 0.0));
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let rings = 0..view.rings().len();
        fresh.cast_rings(origin, &rot, &view, rings.clone(), true, |j, k, h| {
            a.push((j, k, h))
        });
        board.cast_rings(origin, &rot, &view, rings, true, |j, k, h| {
            b.push((j, k, h))
        });
        assert_eq!(a, b);
        assert!(a.iter().any(|(_, _, h)| h.is_some()));
    }
}

/// The unit square at z = 0 with its front towards +z.
fn square_slot() -> [u32; 16] {
    use hemi_hdl_model::format::Coord;
    use hemi_hdl_model::intersect::patch_mem::{PatchWords, KIND_QUAD};
    let c = |x: f32| Coord::from_num(x);
    PatchWords {
        kind: KIND_QUAD,
        v: [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]].map(|[x, y]| [c(x), c(y), c(0.0)]),
        n: [Unit::ZERO, Unit::ZERO, Unit::from_num(1.0 - 1e-9)],
    }
    .encode()
}

/// Pushes one trace entry in `m` and returns the clocks until its result is ready.
fn clocks_to_result(d: &mut Driver<ModelBus>, m: u32, dir: [f32; 3]) -> u32 {
    d.set_mode(m);
    d.push_ray(dir.map(w));
    let mut clocks = 0;
    while d.bus_mut().read(regs::STATUS) & status::RESULT_READY == 0 {
        clocks += 1;
        assert!(clocks < 1000);
    }
    clocks
}

/// A driver on a model of `params` with the unit square loaded and an origin above (0.25, 0.75)
/// whose set-up pass is paid (by a first ray, whose result is left in the FIFO).
fn above_the_square(params: Params) -> Driver<ModelBus> {
    let mut d = Driver::new(ModelBus::with_params(params)).unwrap();
    d.bus_mut().write(regs::CTRL, ctrl::ENABLE);
    d.load_patches([square_slot()]).unwrap();
    let c = |x: f32| hemi_hdl_model::format::Coord::from_num(x).to_bits() as u32;
    d.set_origin([c(0.25), c(0.75), c(1.0)]);
    clocks_to_result(&mut d, mode::TRACE, [0.0, 0.0, -1.0]);
    d
}

/// On the wide datapath a NO_UV entry still takes its place in the unrolled (u,v) pipe: its
/// result leaves on the clock a full one would.
#[test]
fn on_the_wide_datapath_no_uv_results_leave_on_the_same_clock() {
    let wide = Params {
        compact: false,
        ray_groups: 1,
        ..Params::DEFAULT
    };
    let mut d = above_the_square(wide);
    let down = [0.0, 0.0, -1.0];
    let _: [u32; 4] = core::array::from_fn(|_| d.bus_mut().read(regs::RESULT_OUT));
    let full = clocks_to_result(&mut d, mode::TRACE, down);
    let _: [u32; 4] = core::array::from_fn(|_| d.bus_mut().read(regs::RESULT_OUT));
    let short = clocks_to_result(&mut d, mode::TRACE | mode::NO_UV, down);
    assert_eq!(
        short, full,
        "gating the (u,v) stages must not move the result"
    );
}

#[test]
fn no_uv_entries_give_two_word_results_with_the_same_hit_without_the_uv_unit() {
    let mut d = above_the_square(Params::DEFAULT);
    let down = [0.0, 0.0, -1.0];
    let full_r: [u32; 4] = core::array::from_fn(|_| d.bus_mut().read(regs::RESULT_OUT));
    let full = clocks_to_result(&mut d, mode::TRACE, down);
    let long: [u32; 4] = core::array::from_fn(|_| d.bus_mut().read(regs::RESULT_OUT));
    assert_eq!(long, full_r);
    assert_eq!(long[0], result::HIT | result::FRONT);
    let u = Unit::from_bits(long[2] as i32).to_num::<f64>();
    let v = Unit::from_bits(long[3] as i32).to_num::<f64>();
    // 16 levels: within 2^-16 (the point is on a cell boundary at every level from the 2nd)
    assert!(
        (u - 0.25).abs() < 2e-5 && (v - 0.75).abs() < 2e-5,
        "({u}, {v})"
    );

    // MODE.NO_UV: the same hit and t in two words; on the compact datapath the ray does not
    // wait for an iterative (u,v) unit's DEPTH = 16 levels
    let short = clocks_to_result(&mut d, mode::TRACE | mode::NO_UV, down);
    assert_eq!(short + 16, full, "a NO_UV hit skips the (u,v) unit");
    let b = d.bus_mut();
    assert_eq!(b.read(regs::MODE), mode::TRACE | mode::NO_UV);
    let r = [b.read(regs::RESULT_OUT), b.read(regs::RESULT_OUT)];
    assert_eq!(r, [long[0] | result::SHORT, long[1]]);
    // the two reads popped it: nothing is left, and a third read underflows
    assert_eq!(b.read(regs::STATUS) & status::RESULT_READY, 0);
    assert_eq!(b.read(regs::ERROR), 0);
    assert_eq!(b.read(regs::RESULT_OUT), 0);
    assert_eq!(b.read(regs::ERROR), error::RESULT_UNDERFLOW);
    b.write(regs::ERROR, u32::MAX);

    // a miss is short too, and the driver reads either length
    d.set_mode(mode::TRACE | mode::NO_UV);
    let mut got = Vec::new();
    d.stream(
        3,
        |i| [[0.0, 0.0, 1.0], down, [0.0, 0.0, 1.0]][i].map(w),
        |_, r| got.push(r),
    )
    .unwrap();
    assert_eq!(
        got,
        vec![
            [result::SHORT, 0, 0, 0],
            [long[0] | result::SHORT, long[1], 0, 0],
            [result::SHORT, 0, 0, 0]
        ]
    );
    assert_eq!(d.take_errors(), 0);
    // rotations ignore the flag: their results are four words, ROTATED, never SHORT
    d.frame_from_normal([0, 0, w(1.0 - 1e-9)], [w(1.0 - 1e-9), 0]);
    d.wait_idle().unwrap();
    d.set_mode(mode::ROTATE | mode::NO_UV);
    d.push_ray([w(1.0 - 1e-9), 0, 0]);
    let b = d.bus_mut();
    let mut polls = 0;
    while b.read(regs::STATUS) & status::RESULT_READY == 0 {
        polls += 1;
        assert!(polls < 1000);
    }
    let r: [u32; 4] = core::array::from_fn(|_| b.read(regs::RESULT_OUT));
    assert_eq!(r[0], result::ROTATED, "{r:x?}");
    assert!(
        Unit::from_bits(r[1] as i32).to_num::<f64>() > 0.99,
        "{r:x?}"
    );
    assert_eq!(b.read(regs::STATUS) & status::RESULT_READY, 0);
    assert_eq!(b.read(regs::ERROR), 0, "four reads, no underflow");
    // unknown MODE bits are refused and leave MODE as it was
    let b = d.bus_mut();
    b.write(regs::MODE, mode::TRACE | 1 << 4);
    assert_ne!(b.read(regs::ERROR) & error::BAD_CONFIG, 0);
    assert_eq!(b.read(regs::MODE), mode::ROTATE | mode::NO_UV);
}
