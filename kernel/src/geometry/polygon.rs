//! Planar convex polygons: quads and triangles, with the bilinear (u,v) parametrisation the
//! sample points (paper §4.2) and the rendering grids (§5) are placed in.
//!
//! A quad maps the unit square by `P(u,v) = (1-u)(1-v)P0 + u(1-v)P1 + uv P2 + (1-u)v P3`; a
//! triangle is the same map with P3 = P2 (a quad collapsed at its top edge), so one sampling and
//! one interpolation scheme serve both. The front side is the one from which the vertices run
//! counter-clockwise (right-handed): the normal is `(P1-P0)×(P2-P0)` normalised.

use super::Vec3;

/// Why a polygon was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PolygonError {
    /// A coordinate is NaN or infinite.
    NotFinite,
    /// Zero area, or vertices on a line.
    Degenerate,
    /// The fourth vertex is off the plane of the first three.
    NotPlanar,
    /// The quad is not convex (or its vertices are not in order around it).
    NotConvex,
}

/// A planar convex quad or triangle.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Polygon {
    /// Vertices; for a triangle `v[3] == v[2]`.
    pub v: [Vec3; 4],
    /// 3 or 4.
    pub sides: u8,
    /// Unit normal of the front side.
    pub normal: Vec3,
    /// Area.
    pub area: f32,
}

impl Polygon {
    /// A quad from its four vertices in order around it.
    pub fn quad(v: [Vec3; 4]) -> Result<Polygon, PolygonError> {
        Self::build(v, 4)
    }

    /// How far the furthest vertex of quad `v` lies from the plane through `v[0]` with the
    /// diagonals' normal, as a fraction of the quad's size (its largest distance from `v[0]`);
    /// 0 for a degenerate quad. [`Polygon::quad`] refuses more than 1 %; a scene loader may cut
    /// a quad warped less than that into two triangles.
    pub fn warp(v: &[Vec3; 4]) -> f32 {
        let scale = v.iter().fold(0.0f32, |m, p| m.max((*p - v[0]).length()));
        let Some(normal) = (v[2] - v[0]).cross(v[3] - v[1]).try_normalize() else {
            return 0.0;
        };
        if scale.is_nan() || scale <= 0.0 {
            return 0.0;
        }
        let off = v
            .iter()
            .fold(0.0f32, |m, p| m.max((*p - v[0]).dot(normal).abs()));
        off / scale
    }

    /// A triangle.
    pub fn triangle(v: [Vec3; 3]) -> Result<Polygon, PolygonError> {
        Self::build([v[0], v[1], v[2], v[2]], 3)
    }

    fn build(v: [Vec3; 4], sides: u8) -> Result<Polygon, PolygonError> {
        if !v.iter().all(|p| p.is_finite()) {
            return Err(PolygonError::NotFinite);
        }
        let scale = v.iter().fold(0.0f32, |m, p| m.max((*p - v[0]).length()));
        // Newell-style normal from the diagonals: robust for any planar quad and for triangles.
        let cross = if sides == 4 {
            (v[2] - v[0]).cross(v[3] - v[1])
        } else {
            (v[1] - v[0]).cross(v[2] - v[0])
        };
        let area = 0.5 * cross.length();
        if scale.is_nan() || scale <= 0.0 || area <= 1e-10 * scale * scale {
            return Err(PolygonError::Degenerate);
        }
        let normal = cross / (2.0 * area);
        // Measured scene data is rarely exactly planar (the published Cornell box's red wall is
        // warped by 0.20 % of its size): warps up to 1 % are taken as planar with the
        // diagonals' normal; more is refused.
        if sides == 4 && Self::warp(&v) > 1e-2 {
            return Err(PolygonError::NotPlanar);
        }
        if sides == 4 {
            for i in 0..4 {
                let e0 = v[(i + 1) % 4] - v[i];
                let e1 = v[(i + 2) % 4] - v[(i + 1) % 4];
                if e0.cross(e1).dot(normal) <= 1e-7 * scale * scale {
                    return Err(PolygonError::NotConvex);
                }
            }
        }
        Ok(Polygon {
            v,
            sides,
            normal,
            area,
        })
    }

    /// The distinct vertices (3 or 4).
    pub fn vertices(&self) -> &[Vec3] {
        &self.v[..self.sides as usize]
    }

    /// P(u,v), the bilinear map of the unit square onto the polygon.
    pub fn point(&self, u: f32, v: f32) -> Vec3 {
        let a = self.v[0].lerp(self.v[1], u);
        let b = self.v[3].lerp(self.v[2], u);
        a.lerp(b, v)
    }

    /// |∂P/∂u × ∂P/∂v| at (u,v): the area density of the map. For a planar quad it is affine in
    /// u and v, so the midpoint rule integrates it exactly over any (u,v) rectangle, which makes
    /// sample-point weights sum to exactly 1.
    pub fn jacobian(&self, u: f32, v: f32) -> f32 {
        let pu = (self.v[1] - self.v[0]).lerp(self.v[2] - self.v[3], v);
        let pv = (self.v[3] - self.v[0]).lerp(self.v[2] - self.v[1], u);
        pu.cross(pv).length()
    }

    /// The (u,v) of a point on (or near) the polygon: the inverse of [`Polygon::point`], clamped
    /// to the unit square.
    pub fn uv_of(&self, p: Vec3) -> (f32, f32) {
        match self.uv_frame() {
            Some(frame) => frame.uv_of(p),
            None => (0.5, 0.5),
        }
    }

    /// The plane frame [`Polygon::uv_of`] works in, for a caller that inverts many points of
    /// one polygon (the same arithmetic, so the same bits); `None` if the first edge has no
    /// length.
    pub fn uv_frame(&self) -> Option<UvFrame> {
        let e1 = (self.v[1] - self.v[0]).try_normalize()?;
        let e2 = self.normal.cross(e1);
        let to2 = |q: Vec3| {
            let d = q - self.v[0];
            (d.dot(e1), d.dot(e2))
        };
        let (b, c, d) = (to2(self.v[1]), to2(self.v[2]), to2(self.v[3]));
        // the terms of the inversion that do not depend on the point, computed once per
        // polygon by the same operations the per-point formulas would use, so the same bits
        let g = (-b.0 + c.0 - d.0, -b.1 + c.1 - d.1);
        Some(UvFrame {
            origin: self.v[0],
            e1,
            e2,
            sides: self.sides,
            b,
            c,
            d,
            g,
            k2: cross2(g, d),
            ef: cross2(b, d),
            bc: cross2(b, c),
        })
    }
}

/// A polygon's plane in 2-D: its first vertex, two unit axes and the other vertices in them,
/// with the terms of the inverse map that depend only on the polygon: all that
/// [`Polygon::uv_of`] needs besides the point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvFrame {
    origin: Vec3,
    e1: Vec3,
    e2: Vec3,
    sides: u8,
    b: (f32, f32),
    c: (f32, f32),
    d: (f32, f32),
    /// P0 − P1 + P2 − P3 in the plane: the bilinear map's twist (zero on a parallelogram).
    g: (f32, f32),
    /// g × (P3 − P0): the quadratic's leading coefficient.
    k2: f32,
    /// (P1 − P0) × (P3 − P0).
    ef: f32,
    /// (P1 − P0) × (P2 − P0): a triangle's doubled area.
    bc: f32,
}

impl UvFrame {
    fn to2(&self, q: Vec3) -> (f32, f32) {
        let d = q - self.origin;
        (d.dot(self.e1), d.dot(self.e2))
    }

    /// [`Polygon::uv_of`] of the polygon this frame is of.
    pub fn uv_of(&self, p: Vec3) -> (f32, f32) {
        let h = self.to2(p);
        if self.sides == 3 {
            return self.triangle_uv(h);
        }
        self.inverse_bilinear(h)
    }

    /// Barycentric (u,v) for the collapsed-quad triangle map: v is the weight of P2, u the
    /// share of P1 along the bottom edge.
    fn triangle_uv(&self, h: (f32, f32)) -> (f32, f32) {
        let w1 = cross2(h, self.c) / self.bc;
        let w2 = cross2(self.b, h) / self.bc;
        let v = clamp01(w2);
        let u = if v < 1.0 - 1e-6 { w1 / (1.0 - v) } else { 0.5 };
        (clamp01(u), v)
    }

    /// Inverse of the bilinear map with P0 at the origin (Quilez's closed form), all in 2-D:
    /// with e = P1, f = P3 and g the twist, h = e·u + f·v + g·uv is a quadratic in v.
    fn inverse_bilinear(&self, h: (f32, f32)) -> (f32, f32) {
        let (e, f, g, k2) = (self.b, self.d, self.g, self.k2);
        let k1 = self.ef + cross2(h, g);
        let k0 = cross2(h, e);
        let solve_u = |v: f32| {
            let den = (e.0 + g.0 * v, e.1 + g.1 * v);
            if den.0.abs() > den.1.abs() {
                (h.0 - f.0 * v) / den.0
            } else {
                (h.1 - f.1 * v) / den.1
            }
        };
        if k2.abs() <= 1e-6 * self.ef.abs() {
            // a parallelogram (or trapezoid along v): the equation is linear in v
            let v = -k0 / k1;
            return (clamp01(solve_u(v)), clamp01(v));
        }
        let disc = super::sqrt((k1 * k1 - 4.0 * k0 * k2).max(0.0));
        let mut best = (0.5, 0.5);
        let mut best_err = f32::INFINITY;
        for v in [(-k1 - disc) / (2.0 * k2), (-k1 + disc) / (2.0 * k2)] {
            let u = solve_u(v);
            let err = (u - clamp01(u)).abs() + (v - clamp01(v)).abs();
            if err < best_err {
                best_err = err;
                best = (clamp01(u), clamp01(v));
            }
            if err == 0.0 {
                // inside the unit square: the other root cannot do better (it would need a
                // smaller error to be taken), so the hot path of every hit skips its division
                break;
            }
        }
        best
    }
}

fn cross2(a: (f32, f32), b: (f32, f32)) -> f32 {
    a.0 * b.1 - a.1 * b.0
}

fn clamp01(x: f32) -> f32 {
    if x.is_nan() {
        0.5
    } else {
        x.clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn q(p: [[f32; 3]; 4]) -> Result<Polygon, PolygonError> {
        Polygon::quad(p.map(Vec3::from_array))
    }

    #[test]
    fn a_frame_inverts_points_to_the_same_bits_as_uv_of() {
        // a trapezoid-like quad (not a parallelogram: the quadratic branch) and a triangle
        let quad = q([[0., 0., 0.], [3., 0., 0.], [2.5, 1., 0.], [0.2, 1.2, 0.]]).unwrap();
        let tri =
            Polygon::triangle([[0., 0., 1.], [2., 0., 1.], [0.5, 1.5, 1.]].map(Vec3::from_array))
                .unwrap();
        for poly in [quad, tri] {
            let frame = poly.uv_frame().unwrap();
            for n in 0..50 {
                let (u, v) = ((n % 7) as f32 / 6.0, (n / 7) as f32 / 7.0);
                let p = poly.point(u, v) + Vec3::new(0.01, -0.02, 0.0) * (n as f32 / 50.0);
                let (a, b) = (poly.uv_of(p), frame.uv_of(p));
                assert_eq!(
                    (a.0.to_bits(), a.1.to_bits()),
                    (b.0.to_bits(), b.1.to_bits())
                );
            }
        }
    }

    #[test]
    fn normal_follows_counter_clockwise_front() {
        // Cornell floor: counter-clockwise seen from above.
        let f = q([
            [552.8, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 559.2],
            [549.6, 0.0, 559.2],
        ])
        .unwrap();
        assert!((f.normal.y - 1.0).abs() < 1e-6);
        let t = Polygon::triangle(
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]].map(Vec3::from_array),
        )
        .unwrap();
        assert!((t.normal.z - 1.0).abs() < 1e-6 && (t.area - 0.5).abs() < 1e-6);
    }

    #[test]
    fn refuses_bad_polygons() {
        assert_eq!(
            q([[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [3.0, 0.0, 0.0]]),
            Err(PolygonError::Degenerate)
        );
        assert_eq!(
            q([[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.5], [0.0, 1.0, 0.0]]),
            Err(PolygonError::NotPlanar)
        );
        // a dart (concave at its third vertex)
        assert_eq!(
            q([[0.0; 3], [2.0, 0.0, 0.0], [0.5, 0.5, 0.0], [0.0, 2.0, 0.0]]),
            Err(PolygonError::NotConvex)
        );
        // a bow tie: vertices out of order, the diagonals coincide
        assert_eq!(
            q([[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]),
            Err(PolygonError::Degenerate)
        );
        assert_eq!(
            q([
                [f32::NAN, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0]
            ]),
            Err(PolygonError::NotFinite)
        );
    }

    #[test]
    fn uv_inverts_the_bilinear_map() {
        let shapes = [
            q([[0.0; 3], [2.0, 0.0, 0.0], [2.0, 1.0, 0.0], [0.0, 1.0, 0.0]]).unwrap(),
            q([
                [0.0, 0.0, 0.0],
                [3.0, 0.2, 0.0],
                [2.5, 2.0, 0.0],
                [0.3, 1.5, 0.0],
            ])
            .unwrap(),
            q([
                [552.8, 0.0, 0.0],
                [0.0, 0.0, 0.0],
                [0.0, 0.0, 559.2],
                [549.6, 0.0, 559.2],
            ])
            .unwrap(),
            Polygon::triangle(
                [[0.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 1.0, 0.5]].map(Vec3::from_array),
            )
            .unwrap(),
        ];
        for s in shapes {
            for (u, v) in [(0.1, 0.2), (0.5, 0.5), (0.9, 0.05), (0.33, 0.77)] {
                let (uu, vv) = s.uv_of(s.point(u, v));
                assert!(
                    (uu - u).abs() < 1e-3 && (vv - v).abs() < 1e-3,
                    "{s:?} {u},{v} -> {uu},{vv}"
                );
            }
        }
    }

    #[test]
    fn midpoint_jacobian_integrates_area_exactly() {
        let s = q([
            [0.0, 0.0, 0.0],
            [3.0, 0.2, 0.0],
            [2.5, 2.0, 0.0],
            [0.3, 1.5, 0.0],
        ])
        .unwrap();
        let k = 5;
        let mut sum = 0.0;
        for a in 0..k {
            for b in 0..k {
                sum += s.jacobian((a as f32 + 0.5) / k as f32, (b as f32 + 0.5) / k as f32)
                    / (k * k) as f32;
            }
        }
        assert!((sum - s.area).abs() < 1e-4 * s.area, "{sum} vs {}", s.area);
    }
}
