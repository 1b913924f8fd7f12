//! Sample points on patches (paper §4.2): element centre points placed in (u,v), each with the
//! weight W_iq by which its element-to-patch form factors enter the patch form factor (4.3).
//!
//! Uniform K×K grids place element (a, b) at u = (a + ½)/K, v = (b + ½)/K. The paper's weight is
//! the (u,v) area 2^-2n (here 1/K²); on a polygon whose map is not area-preserving (a trapezoid,
//! a triangle) that would bias F_ij, so the weight is the element's true area share
//! J(u,v)/(K² A), which equals 1/K² on parallelograms and sums to exactly 1 on any planar quad
//! (the Jacobian is affine, so the midpoint rule is exact).

use crate::geometry::{Polygon, Vec3};

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
