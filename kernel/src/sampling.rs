//! Sample points on patches (paper §4.2): element centre points placed in (u,v), each with the
//! weight W_iq by which its element-to-patch form factors enter the patch form factor (4.3).
//!
//! Uniform K×K grids place element (a, b) at u = (a + ½)/K, v = (b + ½)/K. The paper's weight is
//! the (u,v) area 2^-2n (here 1/K²); on a polygon whose map is not area-preserving (a trapezoid,
//! a triangle) that would bias F_ij, so the weight is the element's true area share
//! J(u,v)/(K² A), which equals 1/K² on parallelograms and sums to exactly 1 on any planar quad
//! (the Jacobian is affine, so the midpoint rule is exact).

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
