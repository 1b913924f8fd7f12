//! The job engine: jobs answered and counted once, settings and indices refused before any work,
//! the board's rows through mirrors the same bits as the host's tracer, and random requests
//! never a panic.

use super::*;
use crate::link::{AccelKind, ErrorCode, JobConfig, LinkStats, Request, Response};

extern crate std;

/// A job engine on the soft accelerator, configured for R = `circles`, K = 2, one sample per
/// pixel, no camera.
fn configured_engine(circles: u16) -> Engine<crate::jobs::SoftProvider, crate::jobs::NoPlatform> {
    use crate::jobs::{NoPlatform, SoftProvider};
    let mut engine = Engine::new(SoftProvider::new(), NoPlatform);
    let cfg = JobConfig {
        circles,
        rule: crate::hemisphere::DeltaRule::Band,
        samples: 2,
        spp: 1,
        camera: None,
        accel: AccelKind::Soft,
    };
    assert_eq!(
        engine.handle(1, &Request::Configure(cfg)),
        Some(Response::Configured)
    );
    engine
}

#[test]
fn engine_answers_jobs_and_counts_repeats_once() {
    use crate::geometry::{Polygon, Vec3};
    use crate::jobs::{NoPlatform, SoftProvider};
    use crate::patch::Patch;
    let quad = |v: [[f32; 3]; 4]| {
        Patch::polygon(Polygon::quad(v.map(|p| Vec3::new(p[0], p[1], p[2]))).unwrap())
    };
    // Two unit squares facing each other at distance 1.
    let a = quad([[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]]);
    let b = quad([[0., 0., 1.], [0., 1., 1.], [1., 1., 1.], [1., 0., 1.]]);
    let shoot = Request::Shoot {
        patch: 0,
        first: 0,
        count: 4,
    };
    let unconfigured = Engine::new(SoftProvider::new(), NoPlatform).handle(7, &shoot);
    assert_eq!(
        unconfigured,
        Some(Response::Error {
            code: ErrorCode::NoScene
        })
    );
    let mut engine = configured_engine(8);
    engine.handle(2, &Request::SceneBegin { patches: 2 });
    for (i, p) in [a, b].into_iter().enumerate() {
        engine.handle(
            3 + i as u32,
            &Request::ScenePatch {
                index: i as u16,
                area: 1.0,
                patch: p,
            },
        );
    }
    let Some(Response::Rows(rows)) = engine.handle(10, &shoot) else {
        panic!("no rows");
    };
    assert_eq!(rows.lens.len(), 4);
    // F(square → opposite square at distance 1) = 0.1998 (Howell C-11); per sample ~ that.
    for (_, f) in &rows.entries {
        assert!(f[0] > 0.1 && f[0] < 0.4, "{f:?}");
    }
    // The same job id again: same bits, counted once.
    assert_eq!(
        engine.handle(10, &shoot),
        Some(Response::Rows(rows.clone()))
    );
    // A level job on the lattice of the configured K is the same job; a finer one has k² cells.
    let level = |k, first, count| Request::ShootLevel {
        patch: 0,
        k,
        first,
        count,
    };
    assert_eq!(
        engine.handle(11, &level(2, 0, 4)),
        Some(Response::Rows(rows))
    );
    let Some(Response::Rows(fine)) = engine.handle(12, &level(4, 12, 4)) else {
        panic!("no rows at k = 4");
    };
    assert_eq!(fine.lens.len(), 4);
    for (req, what) in [(level(4, 14, 3), "past k²"), (level(0, 0, 1), "k = 0")] {
        assert!(
            matches!(engine.handle(13, &req), Some(Response::Error { .. })),
            "{what}"
        );
    }
    // Out of range and over capacity are refused, not indexed.
    let bad = [
        Request::Shoot {
            patch: 2,
            first: 0,
            count: 1,
        },
        Request::Shoot {
            patch: 0,
            first: 3,
            count: 2,
        },
        Request::Trace { first: 0, count: 1 },
        Request::Gather {
            point: Vec3::ZERO,
            normal: Vec3::ZERO,
            ring: 0,
            first: 0,
            count: 1,
        },
    ];
    for req in &bad {
        assert!(matches!(
            engine.handle(20, req),
            Some(Response::Error { .. })
        ));
    }
    let s = engine.stats(LinkStats::default());
    // the Shoot, the two level jobs; the repeated Shoot; the two bad level jobs and `bad`
    assert_eq!((s.jobs, s.repeats, s.refused), (3, 1, 6), "{s:?}");
    assert!(s.rays > 0);
}

#[test]
fn engine_tables_fit_the_largest_hemisphere() {
    use crate::jobs::{ENGINE_MAX_CIRCLES, ENGINE_MAX_QUARTER};
    assert_eq!(
        crate::hemisphere::quarter_len(ENGINE_MAX_CIRCLES as u32),
        ENGINE_MAX_QUARTER
    );
}

/// A box 2 × 2 × 2 open at z = 2: floor, ceiling, back, a mirror at x = 0 (k_r 0.9, one ray)
/// and a glossy wall at x = 2 (diffuse too, a 3-ring lobe), so frustums bounce between them; at
/// R = 12 with its specular settings.
struct MirrorBox {
    patches: [crate::patch::Patch; 5],
    surfaces: [crate::optics::Surface; 5],
    weights: std::vec::Vec<f32>,
    settings: crate::link::TraceSettings,
    hemi: crate::hemisphere::OwnedHemisphere,
}

impl MirrorBox {
    fn new() -> MirrorBox {
        use crate::geometry::{Polygon, Vec3};
        use crate::hemisphere::{DeltaRule, OwnedHemisphere};
        use crate::optics::{Lobe, Specular, Surface};
        use crate::patch::Patch;
        let quad = |v: [[f32; 3]; 4]| {
            Patch::polygon(Polygon::quad(v.map(|p| Vec3::new(p[0], p[1], p[2]))).unwrap())
        };
        let patches = [
            quad([[0., 0., 0.], [0., 0., 2.], [2., 0., 2.], [2., 0., 0.]]),
            quad([[0., 2., 0.], [2., 2., 0.], [2., 2., 2.], [0., 2., 2.]]),
            quad([[0., 0., 0.], [2., 0., 0.], [2., 2., 0.], [0., 2., 0.]]),
            quad([[0., 0., 0.], [0., 2., 0.], [0., 2., 2.], [0., 0., 2.]]),
            quad([[2., 0., 0.], [2., 0., 2.], [2., 2., 2.], [2., 2., 0.]]),
        ];
        let hemi = OwnedHemisphere::new(12, DeltaRule::Band).unwrap();
        let mut weights = std::vec![1.0f32; 1];
        let mut gloss = [0.0f32; 3];
        crate::frustum::lobe_weights(&hemi.view(), 40.0, 2, &mut gloss).unwrap();
        weights.extend_from_slice(&gloss);
        let mirror = Surface {
            column: None,
            back_column: None,
            reflect: Some(Specular {
                k: [0.9; 3],
                lobe: Lobe { first: 0, size: 0 },
            }),
            transmit: None,
        };
        let glossy = Surface {
            column: Some(3),
            back_column: None,
            reflect: Some(Specular {
                k: [0.5, 0.4, 0.3],
                lobe: Lobe { first: 1, size: 2 },
            }),
            transmit: None,
        };
        let surfaces = [
            Surface::diffuse(0),
            Surface::diffuse(1),
            Surface::diffuse(2),
            mirror,
            glossy,
        ];
        let settings = crate::link::TraceSettings {
            threshold: 0.01,
            max_bounces: 24,
            stack: 16,
        };
        MirrorBox {
            patches,
            surfaces,
            weights,
            settings,
            hemi,
        }
    }

    /// A soft engine with the box uploaded over the link (optics, lobes, settings).
    fn engine(&self) -> Engine<crate::jobs::SoftProvider, crate::jobs::NoPlatform> {
        use crate::link::MAX_LOBE_CHUNK;
        let mut engine = configured_engine(self.hemi.view().circles() as u16);
        assert_eq!(
            engine.handle(2, &Request::Tracing(self.settings)),
            Some(Response::Configured)
        );
        engine.handle(3, &Request::SceneBegin { patches: 5 });
        for (c, chunk) in self.weights.chunks(MAX_LOBE_CHUNK).enumerate() {
            let r = engine.handle(
                4,
                &Request::SceneLobes {
                    first: (c * MAX_LOBE_CHUNK) as u16,
                    weights: heapless::Vec::from_slice(chunk).unwrap(),
                },
            );
            assert!(matches!(r, Some(Response::SceneAck { .. })), "{r:?}");
        }
        for (i, s) in self.surfaces.iter().enumerate() {
            let r = engine.handle(
                5,
                &Request::SceneSurface {
                    index: i as u16,
                    surface: *s,
                },
            );
            assert!(matches!(r, Some(Response::SceneAck { .. })), "{r:?}");
        }
        for (i, p) in self.patches.iter().enumerate() {
            engine.handle(
                6,
                &Request::ScenePatch {
                    index: i as u16,
                    area: 4.0,
                    patch: *p,
                },
            );
        }
        engine
    }

    /// Runs `f` with the host's way of tracing: a soft accelerator over the box and a park for
    /// the whole hemisphere (one cast per shot).
    fn on_host<R>(
        &self,
        f: impl FnOnce(
            &mut crate::accel::soft::SoftAccelerator<'_, '_>,
            &crate::optics::Optics<'_>,
            &mut crate::tracer::TraceScratch<'_>,
        ) -> R,
    ) -> R {
        use crate::accel::soft::{LocalPatch, SoftAccelerator, SoftScratch};
        use crate::optics::Optics;
        use crate::skeleton::{Frame, Skeleton};
        use crate::specular::Pending;
        use crate::tracer::TraceScratch;
        let view = self.hemi.view();
        let optics =
            Optics::new(&self.patches, &self.surfaces, &self.weights, view.circles()).unwrap();
        let mut local = [LocalPatch::default(); 5];
        let (mut bt, mut bi) = ([0.0f32; 64], [0u32; 64]);
        let mut pending = std::vec![Pending::EMPTY; view.ray_count() as usize];
        let mut parked = std::vec![Pending::EMPTY; 4096];
        let mut frames = [Frame::EMPTY; 16];
        let scratch = SoftScratch {
            local: &mut local,
            best_t: &mut bt,
            best_id: &mut bi,
        };
        let mut accel = SoftAccelerator::new(&self.patches, scratch).unwrap();
        let mut scratch = TraceScratch {
            pending: &mut pending,
            parked: &mut parked,
            skeleton: Skeleton::new(&mut frames),
            threshold: self.settings.threshold,
            max_depth: self.settings.max_bounces,
        };
        f(&mut accel, &optics, &mut scratch)
    }
}

#[test]
fn engine_rows_through_mirrors_equal_the_tracer_with_a_whole_hemisphere_park() {
    use crate::geometry::Vec3;
    use crate::jobs::ENGINE_PENDING;
    use crate::link::TraceStats;
    use crate::rotation::spin_for_sample;
    use crate::sampling::uniform_sample;
    use crate::tracer::shoot_hemisphere;
    use std::vec;
    let scene = MirrorBox::new();
    let (patches, surfaces) = (&scene.patches, &scene.surfaces);
    let view = scene.hemi.view();

    // The host's way: a park for the whole hemisphere, one cast per shot.
    let samples = 4u32;
    let mut expected = vec![];
    let mut host_frustums = 0;
    for (i, p) in patches.iter().enumerate() {
        if surfaces[i].column.is_none() {
            continue;
        }
        let mut rows = vec![];
        for q in 0..samples {
            let point = uniform_sample(&p.shape, 4.0, 2, q);
            let mut row = [[0.0f32; 3]; 4];
            let shot = scene.on_host(|accel, optics, scratch| {
                shoot_hemisphere(
                    accel,
                    &view,
                    optics,
                    scratch,
                    point.position,
                    point.normal,
                    spin_for_sample(q),
                    Some(i as u32),
                    &mut row[..],
                )
            });
            assert_eq!(shot.specular.recasts, 0);
            host_frustums += shot.specular.frustums;
            rows.push(row);
        }
        expected.push((i, rows));
    }
    assert!(host_frustums > 0);

    // The board's way: the optics uploaded over the link, a park of ENGINE_PENDING hits.
    let mut engine = scene.engine();
    let too_deep = crate::link::TraceSettings {
        stack: 17,
        ..scene.settings
    };
    assert_eq!(
        engine.handle(2, &Request::Tracing(too_deep)),
        Some(Response::Error {
            code: ErrorCode::TooLong
        })
    );
    for (k, (i, rows)) in expected.iter().enumerate() {
        let shoot = Request::Shoot {
            patch: *i as u16,
            first: 0,
            count: samples as u16,
        };
        let Some(Response::Rows(got)) = engine.handle(100 + k as u32, &shoot) else {
            panic!("no rows for patch {i}");
        };
        let mut entries = got.entries.iter();
        for (r, len) in got.lens.iter().enumerate() {
            let mut want = vec![];
            for (c, f) in rows[r].iter().enumerate() {
                if *f != [0.0; 3] {
                    want.push((c as u16, f.map(f32::to_bits)));
                }
            }
            let have: std::vec::Vec<_> = entries
                .by_ref()
                .take(usize::from(*len))
                .map(|(c, f)| (*c, f.map(f32::to_bits)))
                .collect();
            assert_eq!(have, want, "patch {i} sample {r}");
        }
    }
    let Some(Response::TraceStats(t)) = engine.handle(200, &Request::TraceStats) else {
        panic!("no trace stats");
    };
    let t: TraceStats = t;
    assert_eq!(t.frustums, host_frustums);
    assert!(t.stack_high_water >= 1 && t.stack_high_water <= 16, "{t:?}");
    assert_eq!(usize::from(t.pending_capacity), ENGINE_PENDING);
    // the mirror takes more primary hits than the board parks: it cast again, same rows
    assert!(t.recasts > 0, "{t:?}");
    // pass 2 and irradiance through mirrors are refused, not answered wrong
    assert!(matches!(
        engine.handle(
            300,
            &Request::Gather {
                point: Vec3::new(1.0, 1.0, 1.0),
                normal: Vec3::new(0.0, 1.0, 0.0),
                ring: 0,
                first: 0,
                count: 1,
            }
        ),
        Some(Response::Error {
            code: ErrorCode::Unsupported
        })
    ));
}

#[test]
fn hemisphere_windows_through_mirrors_are_the_tracers_reports_in_its_order() {
    // The field's job (protocol 5): a sample point's hemisphere through the mirror and the
    // glossy wall, read a window at a time from a board's small park, gives the reports the
    // host's tracer gives in one go: same order, same bits, same paths, same ray counts.
    use crate::geometry::Vec3;
    use crate::link::{PathHit, MAX_PATHS};
    use crate::tracer::{shoot, Shot};
    let scene = MirrorBox::new();
    let view = scene.hemi.view();
    let mut engine = scene.engine();
    let mut mirrored = 0;
    for (q, (origin, normal, patch)) in [
        (
            Vec3::new(1.3, 0.0, 0.7),
            Vec3::new(0.0, 1.0, 0.0),
            Some(0u16),
        ),
        (Vec3::new(0.4, 2.0, 1.1), -Vec3::new(0.0, 1.0, 0.0), Some(1)),
        (Vec3::new(1.0, 1.0, 1.0), Vec3::new(-1.0, 0.2, 0.1), None),
    ]
    .into_iter()
    .enumerate()
    {
        let shot = Shot {
            origin,
            normal,
            spin: 0.37 * q as f32,
            origin_patch: patch.map(u32::from),
            want_uv: true,
        };
        let mut want = std::vec::Vec::new();
        let stats = scene.on_host(|accel, optics, scratch| {
            shoot(accel, &view, optics, scratch, &shot, |h, weight, via| {
                want.push(PathHit {
                    patch: h.patch as u16,
                    u: h.u,
                    v: h.v,
                    weight,
                    via,
                })
            })
        });
        let mut got = std::vec::Vec::new();
        while got.len() < want.len() || got.is_empty() {
            let req = Request::Hemisphere {
                origin,
                normal,
                spin: shot.spin,
                origin_patch: patch,
                skip: got.len() as u16,
            };
            let Some(Response::Paths(w)) = engine.handle(1000 + got.len() as u32, &req) else {
                panic!("no paths");
            };
            assert_eq!(w.total as usize, want.len());
            assert_eq!(
                (w.rays as u64, w.back_hits as u64),
                (stats.rays, stats.back_hits)
            );
            assert!(w.hits.len() == MAX_PATHS || got.len() + w.hits.len() == want.len());
            if w.hits.is_empty() {
                break;
            }
            got.extend(w.hits);
        }
        let bits = |h: &PathHit| {
            (
                h.patch,
                h.u.to_bits(),
                h.v.to_bits(),
                h.weight.map(f32::to_bits),
                h.via,
            )
        };
        assert_eq!(
            got.iter().map(bits).collect::<std::vec::Vec<_>>(),
            want.iter().map(bits).collect::<std::vec::Vec<_>>()
        );
        mirrored += want
            .iter()
            .filter(|h| h.via.mirror && h.via.bounces == 1)
            .count();
    }
    assert!(mirrored > 0, "some reports came once through the mirror");
    // a shot standing on a patch the scene lacks is refused
    let bad = Request::Hemisphere {
        origin: Vec3::new(1.0, 1.0, 1.0),
        normal: Vec3::new(0.0, 1.0, 0.0),
        spin: 0.0,
        origin_patch: Some(5),
        skip: 0,
    };
    assert!(matches!(
        engine.handle(2000, &bad),
        Some(Response::Error {
            code: ErrorCode::OutOfRange
        })
    ));
}

#[test]
fn cast_answers_each_rays_nearest_hit_with_its_distance() {
    use crate::accel::{Accelerator, Ray};
    use crate::geometry::Vec3;
    use crate::link::{CastHit, MAX_CAST};
    let scene = MirrorBox::new();
    let mut engine = scene.engine();
    let rays: heapless::Vec<(Vec3, Vec3), MAX_CAST> = (0..MAX_CAST)
        .map(|i| {
            let a = i as f32 * 0.37;
            (
                Vec3::new(1.0, 1.0, 1.0),
                Vec3::new(a.cos(), a.sin(), 0.3 - 0.02 * i as f32),
            )
        })
        .collect();
    let want: std::vec::Vec<Option<CastHit>> = scene.on_host(|accel, _, _| {
        rays.iter()
            .map(|&(origin, dir)| {
                accel
                    .nearest_hit(&Ray { origin, dir }, f32::INFINITY)
                    .map(|h| CastHit {
                        patch: h.patch as u16,
                        front: h.front,
                        t: h.t,
                        u: h.u,
                        v: h.v,
                    })
            })
            .collect()
    });
    let Some(Response::Nearest(got)) = engine.handle(10, &Request::Cast { rays: rays.clone() })
    else {
        panic!("no answer");
    };
    assert_eq!(got.as_slice(), want.as_slice());
    assert!(want.iter().flatten().any(|h| h.t > 0.5 && h.front));
    // a ray without a direction is refused, not cast
    let mut bad = rays;
    bad[3].1 = Vec3::ZERO;
    assert!(matches!(
        engine.handle(11, &Request::Cast { rays: bad }),
        Some(Response::Error {
            code: ErrorCode::OutOfRange
        })
    ));
}

#[test]
fn random_job_requests_on_a_loaded_scene_are_answered_never_panicking() {
    // The firmware never panics on what arrives on the wire: with a scene loaded (a mirror, a
    // translucent sheet with its back column, a plain quad), jobs with random fields, NaN and
    // infinite vectors, k = 0 and k² past u16, back sides and origin patches past the patches,
    // empty casts and skips past the reports, all get an answer.
    use crate::geometry::{Polygon, Vec3};
    use crate::optics::{Lobe, Specular, Surface};
    use crate::patch::Patch;
    let quad = |z: f32| {
        Patch::polygon(
            Polygon::quad(
                [[0., 0.], [1., 0.], [1., 1.], [0., 1.]].map(|[x, y]| Vec3::new(x, y, z)),
            )
            .unwrap(),
        )
    };
    let mut engine = configured_engine(4);
    engine.handle(2, &Request::SceneBegin { patches: 3 });
    let lobes = [1.0f32, 0.5, 0.25];
    engine.handle(
        3,
        &Request::SceneLobes {
            first: 0,
            weights: heapless::Vec::from_slice(&lobes).unwrap(),
        },
    );
    let mirror = Surface {
        column: None,
        back_column: None,
        reflect: Some(Specular {
            k: [0.9; 3],
            lobe: Lobe { first: 0, size: 1 },
        }),
        transmit: None,
    };
    let sheet = Surface {
        back_column: Some(3),
        ..Surface::diffuse(1)
    };
    for (i, s) in [mirror, sheet].into_iter().enumerate() {
        let r = engine.handle(
            4,
            &Request::SceneSurface {
                index: i as u16,
                surface: s,
            },
        );
        assert!(matches!(r, Some(Response::SceneAck { .. })), "{r:?}");
    }
    for (i, z) in [0.0f32, 1.0, 2.0].into_iter().enumerate() {
        engine.handle(
            5,
            &Request::ScenePatch {
                index: i as u16,
                area: 1.0,
                patch: quad(z),
            },
        );
    }
    let mut x = 0x1234_5678_9abc_def1u64;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let (mut answered_rows, mut answered_queries, mut answered_casts) = (0, 0, 0);
    for id in 10..2010u32 {
        let small = |v: u64| (v % 8) as u16;
        let any = |v: u64| v as u16;
        let pick = |v: u64, w: u64| {
            if v.is_multiple_of(2) {
                small(w)
            } else {
                any(w)
            }
        };
        let f = |v: u64| match v % 5 {
            0 => f32::NAN,
            1 => f32::INFINITY,
            2 => 0.0,
            _ => (v % 1000) as f32 / 250.0 - 2.0,
        };
        let vec = |a: u64, b: u64, c: u64| Vec3::new(f(a), f(b), f(c));
        let g = |v: u64| (v % 1000) as f32 / 250.0 - 1.998;
        let plain = |a: u64, b: u64, c: u64| Vec3::new(g(a), g(b), g(c));
        let req = match next() % 6 {
            0 => Request::ShootLevel {
                patch: pick(next(), next()),
                k: pick(next(), next()),
                first: pick(next(), next()),
                count: pick(next(), next()),
            },
            1 => Request::Shoot {
                patch: pick(next(), next()),
                first: pick(next(), next()),
                count: pick(next(), next()),
            },
            2 => Request::Query {
                point: vec(next(), next(), next()),
                normal: vec(next(), next(), next()),
                skip: pick(next(), next()),
            },
            3 => Request::Hemisphere {
                origin: vec(next(), next(), next()),
                normal: vec(next(), next(), next()),
                spin: f(next()),
                origin_patch: Some(pick(next(), next())).filter(|_| next() % 3 > 0),
                skip: pick(next(), next()),
            },
            4 => Request::Cast {
                // mostly plain rays: one NaN or zero among many refuses the whole job
                rays: (0..pick(next(), next()) % 48)
                    .map(|_| match next() % 16 {
                        0 => (vec(next(), next(), next()), vec(next(), next(), next())),
                        _ => (plain(next(), next(), next()), plain(next(), next(), next())),
                    })
                    .take(crate::link::MAX_CAST)
                    .collect(),
            },
            _ => Request::Gather {
                point: vec(next(), next(), next()),
                normal: vec(next(), next(), next()),
                ring: pick(next(), next()),
                first: pick(next(), next()),
                count: pick(next(), next()),
            },
        };
        match engine.handle(id, &req) {
            Some(Response::Rows(_)) => answered_rows += 1,
            Some(Response::Weighted(_) | Response::Paths(_)) => answered_queries += 1,
            Some(Response::Nearest(_)) => answered_casts += 1,
            Some(_) => {}
            None => panic!("{req:?} unanswered"),
        }
    }
    // the test reached the shooting paths, not only the refusals
    assert!(
        answered_rows > 10 && answered_queries > 10 && answered_casts > 10,
        "{answered_rows} {answered_queries} {answered_casts}"
    );
}
