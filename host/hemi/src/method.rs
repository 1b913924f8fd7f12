//! Which pass-1 method shoots a sample point (`--method`): the paper's hemisphere, or one of the
//! peers of [`hemi_kernel::peers`] at the same ray budget, for side-by-side charts.

use anyhow::{bail, Result};
use hemi_kernel::accel::Accelerator;
use hemi_kernel::form_row::FormRow;
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::{ray_count, Hemisphere};
use hemi_kernel::optics::Optics;
use hemi_kernel::peers::hemicube::{shoot_hemicube, Hemicube};
use hemi_kernel::peers::monte_carlo::{shoot_monte_carlo, MonteCarlo};
use hemi_kernel::peers::{PeerError, Placement};
use hemi_kernel::rotation::spin_for_sample;
use hemi_kernel::sampling::SamplePoint;
use hemi_kernel::tracer::{shoot_hemisphere, ShotStats, TraceScratch};

/// A pass-1 method. The peers take their ray budget from R: the hemisphere of R circles shoots
/// `ray_count(R)` rays, the hemicube the even n with 3n² closest to that, Monte Carlo the
/// largest stratified grid not above it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Method {
    /// The paper's hemisphere of R circles (§3.2).
    #[default]
    Hemisphere,
    /// Cohen & Greenberg's hemicube.
    Hemicube,
    /// Cosine-weighted Monte Carlo directions, stratified or not.
    MonteCarlo {
        /// Jittered a × b strata (the CLI's `monte-carlo`) or independent directions
        /// (`monte-carlo-plain`).
        stratified: bool,
    },
}

impl Method {
    /// The name `--method` takes.
    pub fn name(self) -> &'static str {
        match self {
            Method::Hemisphere => "hemisphere",
            Method::Hemicube => "hemicube",
            Method::MonteCarlo { stratified: true } => "monte-carlo",
            Method::MonteCarlo { stratified: false } => "monte-carlo-plain",
        }
    }

    /// Rays per sample point at R circles.
    pub fn rays_for(self, circles: u32) -> u32 {
        let budget = ray_count(circles);
        match self {
            Method::Hemisphere => budget,
            Method::Hemicube => Hemicube::for_rays(budget).ray_count(),
            Method::MonteCarlo { stratified } => MonteCarlo::new(budget, stratified)
                .map(|m| m.ray_count())
                .unwrap_or(0),
        }
    }

    /// Refuses what the method cannot do with this scene's optics.
    pub fn check(self, optics: &Optics<'_>) -> Result<()> {
        if self != Method::Hemisphere && optics.has_specular() {
            bail!(
                "--method {}: the scene has specular surfaces, and the peer methods compute direct form factors only (use --method hemisphere)",
                self.name()
            );
        }
        Ok(())
    }
}

impl std::str::FromStr for Method {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> Result<Method> {
        Ok(match s {
            "hemisphere" => Method::Hemisphere,
            "hemicube" => Method::Hemicube,
            "monte-carlo" => Method::MonteCarlo { stratified: true },
            "monte-carlo-plain" => Method::MonteCarlo { stratified: false },
            _ => bail!(
                "--method {s}: expected hemisphere, hemicube, monte-carlo or monte-carlo-plain"
            ),
        })
    }
}

/// Rays per `cast_from` batch of the peers: large enough that the per-batch patch set-up of the
/// soft engine is a few per cent of the batch's cost on scenes of tens of patches.
pub const BATCH: usize = 1024;

/// Per-thread state of one method: the direction batch of the peers.
pub struct Shooter {
    method: Method,
    circles: u32,
    batch: Vec<Vec3>,
}

impl Shooter {
    /// A shooter for `method` at R = `circles`.
    pub fn new(method: Method, circles: u32) -> Shooter {
        let batch = if method == Method::Hemisphere {
            Vec::new()
        } else {
            vec![Vec3::ZERO; BATCH]
        };
        Shooter {
            method,
            circles,
            batch,
        }
    }

    /// Shoots sample point `point` (index `q` on patch `patch`) and accumulates its element row
    /// into `row` (zeroed by the caller), as [`shoot_hemisphere`] does.
    #[expect(clippy::too_many_arguments, reason = "the inputs of one shot")]
    pub fn shoot<A: Accelerator, R: FormRow + ?Sized>(
        &mut self,
        accel: &mut A,
        hemi: &Hemisphere<'_>,
        optics: &Optics<'_>,
        scratch: &mut TraceScratch<'_>,
        point: &SamplePoint,
        q: u32,
        patch: usize,
        row: &mut R,
    ) -> Result<ShotStats> {
        let spin = spin_for_sample(q);
        let at = Placement {
            origin: point.position,
            normal: point.normal,
            spin,
            origin_patch: Some(patch as u32),
        };
        let budget = ray_count(self.circles);
        let peer = |r: Result<ShotStats, PeerError>| {
            r.map_err(|e| anyhow::anyhow!("--method {}: {e:?}", self.method.name()))
        };
        match self.method {
            Method::Hemisphere => Ok(shoot_hemisphere(
                accel,
                hemi,
                optics,
                scratch,
                at.origin,
                at.normal,
                spin,
                at.origin_patch,
                row,
            )),
            Method::Hemicube => peer(shoot_hemicube(
                accel,
                &Hemicube::for_rays(budget),
                optics,
                &at,
                &mut self.batch,
                row,
            )),
            Method::MonteCarlo { stratified } => {
                let mc = MonteCarlo::new(budget, stratified)
                    .map_err(|e| anyhow::anyhow!("--method monte-carlo: {e:?}"))?;
                let seed = ((patch as u64) << 32) | q as u64;
                peer(shoot_monte_carlo(
                    accel,
                    &mc,
                    optics,
                    &at,
                    seed,
                    &mut self.batch,
                    row,
                ))
            }
        }
    }
}
