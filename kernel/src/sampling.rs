//! Sample points on patches (paper §4.2): element centre points placed in (u,v), each with the
//! weight W_iq by which its element-to-patch form factors enter the patch form factor (4.3).
//!
//! Uniform K×K grids place element (a, b) at u = (a + ½)/K, v = (b + ½)/K. The paper's weight is
//! the (u,v) area 2^-2n (here 1/K²); on a polygon whose map is not area-preserving (a trapezoid,
//! a triangle) that would bias F_ij, so the weight is the element's true area share
//! J(u,v)/(K² A), which equals 1/K² on parallelograms and sums to exactly 1 on any planar quad
//! (the Jacobian is affine, so the midpoint rule is exact).
//!
//! Which points a patch gets (the *lattice rule*) is written once, here, for the host's pass 1
//! and adaptive sampling and for a board's job engine, so that their rows agree bit for bit:
//! [`uniform_side`], [`uniform_count`] and [`uniform_sample`], with [`SamplePoint::flipped`] for
//! the back sides of translucent sheets.

use crate::geometry::{Bezier, Polygon, Vec3};
use crate::patch::Shape;

/// One sample point: where a hemisphere is placed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SamplePoint {
    /// Position on the surface.
    pub position: Vec3,
    /// Unit normal of the front side there.
    pub normal: Vec3,
    /// Parametric u of the element centre.
    pub u: f32,
    /// Parametric v of the element centre.
    pub v: f32,
    /// W_iq: the element's share of the patch area.
    pub weight: f32,
}

impl SamplePoint {
    /// The same point for the back side of a translucent sheet: a back side shoots its
    /// hemispheres from its front's points, facing the other way, so only the normal turns
    /// (position, (u,v) and weight are the front's, which keeps the two sides' rows in
    /// lockstep). Negation is exact, so flipping twice gives the point back bit for bit.
    pub fn flipped(self) -> SamplePoint {
        SamplePoint {
            normal: -self.normal,
            ..self
        }
    }
}

/// Sample points per side of a Bezier patch's uniform grid: paper §7 places 4×4 on every
/// patch, whatever K (two subdivisions, whose corners give the normals).
pub const BEZIER_SIDE: u32 = 4;

/// The side of the uniform sample lattice of a patch of shape `shape` for K×K sampling (also the
/// initial level of adaptive sampling): K on a polygon, [`BEZIER_SIDE`] on a Bezier patch
/// whatever K, and 0 unless the patch is `diffuse`: a pure mirror has no form-factor column, so
/// its points would shoot rows nobody reads. The back side of a translucent sheet has its
/// front's lattice (its points are the front's, [`SamplePoint::flipped`]).
pub fn uniform_side(shape: &Shape, diffuse: bool, k: u32) -> u32 {
    match shape {
        _ if !diffuse => 0,
        Shape::Polygon(_) => k,
        Shape::Bezier(_) => BEZIER_SIDE,
    }
}

/// How many sample points a patch gets under K×K sampling ([`uniform_side`] squared, saturating):
/// K² on a polygon, 16 on a Bezier patch, none on a pure mirror.
pub fn uniform_count(shape: &Shape, diffuse: bool, k: u32) -> u32 {
    let side = uniform_side(shape, diffuse, k);
    side.saturating_mul(side)
}

/// Sample point `q` (v-major: q = b·side + a) of the uniform K×K sampling of a diffuse patch of
/// shape `shape` and area `area`: [`grid_sample`] on a polygon, [`bezier_sample`] on a Bezier
/// patch (the 4×4 of §7, whatever K), both cells of [`lattice_sample`] with the side of
/// [`uniform_side`]. Whether the patch is diffuse is for [`uniform_count`] to say: this places
/// the point the lattice has there. For the back side of a translucent sheet, flip the front's
/// point ([`SamplePoint::flipped`]).
pub fn uniform_sample(shape: &Shape, area: f32, k: u32, q: u32) -> SamplePoint {
    let side = uniform_side(shape, true, k).max(1);
    lattice_sample(shape, area, side, q % side, q / side)
}

/// The centre of the (u,v) cell `[u0, u0+du] × [v0, v0+dv]` on `poly`, as a sample point.
pub fn cell_sample(poly: &Polygon, u0: f32, v0: f32, du: f32, dv: f32) -> SamplePoint {
    let u = u0 + 0.5 * du;
    let v = v0 + 0.5 * dv;
    SamplePoint {
        position: poly.point(u, v),
        normal: poly.normal,
        u,
        v,
        weight: poly.jacobian(u, v) * du * dv / poly.area,
    }
}

/// Sample point (a, b) of the uniform K×K grid on `poly` (a along u, b along v).
pub fn grid_sample(poly: &Polygon, k: u32, a: u32, b: u32) -> SamplePoint {
    let d = 1.0 / k as f32;
    cell_sample(poly, a as f32 * d, b as f32 * d, d, d)
}

/// Area of the cell `[u0, u0+du] × [v0, v0+dv]` of a Bezier patch: 4×4-point Gauss–Legendre
/// quadrature of |∂P/∂u × ∂P/∂v| (exact to 1e-6 on the teapot's patches at cell size ¼).
pub fn bezier_cell_area(b: &Bezier, u0: f32, v0: f32, du: f32, dv: f32) -> f32 {
    const X: [f32; 4] = [0.069_431_84, 0.330_009_5, 0.669_990_5, 0.930_568_2];
    const W: [f32; 4] = [0.173_927_4, 0.326_072_6, 0.326_072_6, 0.173_927_4];
    let mut a = 0.0;
    for (xi, wi) in X.iter().zip(W) {
        for (xj, wj) in X.iter().zip(W) {
            let (pu, pv) = b.derivatives(u0 + xi * du, v0 + xj * dv);
            a += wi * wj * pu.cross(pv).length();
        }
    }
    a * du * dv
}

/// Area of a Bezier patch (16 cells of [`bezier_cell_area`]).
pub fn bezier_area(b: &Bezier) -> f32 {
    let mut a = 0.0;
    for r in 0..4 {
        for c in 0..4 {
            a += bezier_cell_area(b, c as f32 * 0.25, r as f32 * 0.25, 0.25, 0.25);
        }
    }
    a
}

/// Sample point (a, b), 0 ≤ a, b < 4, of a Bezier patch (paper §7): the centre
/// u = (2a+1)/8, v = (2b+1)/8 of the sub-patch left after two subdivisions, with the normal from
/// that sub-patch's four corners (the cross product of its diagonals). Where a pole collapses
/// the corners so that the diagonals are parallel, the analytic normal at the centre is used.
/// `area` is the whole patch's area (for the weight).
pub fn bezier_sample(patch: &Bezier, a: u32, b: u32, area: f32) -> SamplePoint {
    bezier_cell_sample(patch, a as f32 * 0.25, b as f32 * 0.25, 0.25, 0.25, area)
}

/// The centre of the (u,v) cell `[u0, u0+du] × [v0, v0+dv]` of a Bezier patch as a sample
/// point, the §7 rule at any subdivision depth (adaptive patch sampling refines Bezier patches
/// in the same (u,v) hierarchy as polygons, §7 last paragraph): the normal from the cell's four
/// corners (or the analytic one where a pole makes the diagonals parallel), the weight the
/// cell's area over `area`, the whole patch's.
pub fn bezier_cell_sample(
    patch: &Bezier,
    u0: f32,
    v0: f32,
    du: f32,
    dv: f32,
    area: f32,
) -> SamplePoint {
    let (u, v) = (u0 + 0.5 * du, v0 + 0.5 * dv);
    let p00 = patch.point(u0, v0);
    let p10 = patch.point(u0 + du, v0);
    let p01 = patch.point(u0, v0 + dv);
    let p11 = patch.point(u0 + du, v0 + dv);
    let diag = (p11 - p00).cross(p01 - p10);
    let scale = (p11 - p00).length() * (p01 - p10).length();
    let normal = if diag.length() > 1e-4 * scale {
        diag.try_normalize()
    } else {
        None
    }
    .or_else(|| patch.normal_near(u, v))
    .unwrap_or(Vec3::Z);
    SamplePoint {
        position: patch.point(u, v),
        normal,
        u,
        v,
        weight: if area > 0.0 {
            bezier_cell_area(patch, u0, v0, du, dv) / area
        } else {
            du * dv
        },
    }
}

/// Sample point (a, b) of the k×k lattice of level cells on a patch of shape `shape` (adaptive sampling, §4.3 and
/// §7 last paragraph): a polygon's [`grid_sample`], a Bezier patch's [`bezier_cell_sample`] of
/// the cell with side 1/k. `area` is the whole patch's. The host's adaptive sampling and a
/// board's level jobs both place their points with this, so their rows agree bit for bit.
pub fn lattice_sample(shape: &Shape, area: f32, k: u32, a: u32, b: u32) -> SamplePoint {
    match shape {
        Shape::Polygon(poly) => grid_sample(poly, k, a, b),
        Shape::Bezier(bez) => {
            let d = 1.0 / k as f32;
            bezier_cell_sample(bez, a as f32 * d, b as f32 * d, d, d, area)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every field's bits, so the comparison is bit for bit (`-0.0 == 0.0` would hide a change).
    fn bits(p: SamplePoint) -> [[u32; 3]; 3] {
        let v = |v: Vec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
        let rest = [p.u.to_bits(), p.v.to_bits(), p.weight.to_bits()];
        [v(p.position), v(p.normal), rest]
    }

    fn trapezoid() -> Polygon {
        let v = [[0., 0.], [3., 0.], [2., 1.], [1., 1.]].map(|[x, y]| Vec3::new(x, y, 0.5));
        Polygon::quad(v).unwrap()
    }

    fn bump() -> Bezier {
        let mut cp = [Vec3::ZERO; 16];
        for (n, c) in cp.iter_mut().enumerate() {
            let (i, j) = ((n % 4) as f32, (n / 4) as f32);
            *c = Vec3::new(i, j, 0.3 * (i * j).sin());
        }
        Bezier::new(cp).unwrap()
    }

    #[test]
    fn the_uniform_rule_places_the_grids_of_polygons_and_the_4x4_of_bezier_patches() {
        let poly = trapezoid();
        let shape = Shape::Polygon(poly);
        for k in [1u32, 3, 16] {
            assert_eq!(uniform_count(&shape, true, k), k * k);
            for q in 0..k * k {
                let want = grid_sample(&poly, k, q % k, q / k);
                assert_eq!(bits(uniform_sample(&shape, poly.area, k, q)), bits(want));
            }
        }
        let bez = bump();
        let area = bezier_area(&bez);
        let shape = Shape::Bezier(bez);
        for k in [1u32, 4, 16] {
            assert_eq!(uniform_side(&shape, true, k), BEZIER_SIDE);
            assert_eq!(uniform_count(&shape, true, k), 16);
            for q in 0..16 {
                let want = bezier_sample(&bez, q % 4, q / 4, area);
                assert_eq!(
                    bits(uniform_sample(&shape, area, k, q)),
                    bits(want),
                    "k {k} q {q}"
                );
            }
        }
    }

    #[test]
    fn a_mirror_gets_no_points_and_a_back_side_its_fronts_flipped() {
        let shape = Shape::Polygon(trapezoid());
        assert_eq!(uniform_count(&shape, false, 8), 0);
        assert_eq!(uniform_count(&Shape::Bezier(bump()), false, 8), 0);
        let front = uniform_sample(&shape, 2.0, 3, 4);
        let back = front.flipped();
        assert_eq!(back.normal, -front.normal);
        assert_eq!(
            (back.position, back.u, back.v, back.weight),
            (front.position, front.u, front.v, front.weight)
        );
        assert_eq!(bits(back.flipped()), bits(front));
    }
}
