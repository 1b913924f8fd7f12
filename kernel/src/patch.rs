//! A patch: one surface of the scene as the ray engine stores it (its "patch memory").

use crate::geometry::{Aabb, Bezier, Polygon, Vec3};

/// The shape of a patch.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Shape {
    /// A planar convex quad or triangle.
    Polygon(Polygon),
    /// A bicubic Bezier patch (paper §7).
    Bezier(Bezier),
}

/// One patch of the scene. Its index in the patch slice is its id: the column of the form-factor
/// row a hit on its front side adds to. Back sides block rays but neither emit nor reflect.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Patch {
    /// The surface.
    pub shape: Shape,
}

impl Patch {
    /// A polygonal patch.
    pub fn polygon(p: Polygon) -> Patch {
        Patch {
            shape: Shape::Polygon(p),
        }
    }
    /// A Bezier patch.
    pub fn bezier(b: Bezier) -> Patch {
        Patch {
            shape: Shape::Bezier(b),
        }
    }
    /// The polygon, for the planar shapes.
    pub fn as_polygon(&self) -> Option<&Polygon> {
        match &self.shape {
            Shape::Polygon(p) => Some(p),
            Shape::Bezier(_) => None,
        }
    }
    /// The points whose convex hull contains the patch (vertices, or control points).
    pub fn hull(&self) -> &[Vec3] {
        match &self.shape {
            Shape::Polygon(p) => p.vertices(),
            Shape::Bezier(b) => &b.cp,
        }
    }
    /// The patch's bounding box.
    pub fn bounds(&self) -> Aabb {
        Aabb::of(self.hull())
    }
    /// The unit normal of the front side at (u, v): the plane's normal for a polygon; for a
    /// Bezier patch the surface normal (its limit from inside at a pole, +z if the patch is
    /// degenerate everywhere near (u, v)).
    pub fn normal_at(&self, u: f32, v: f32) -> Vec3 {
        match &self.shape {
            Shape::Polygon(p) => p.normal,
            Shape::Bezier(b) => b.normal_near(u, v).unwrap_or(Vec3::Z),
        }
    }
}
