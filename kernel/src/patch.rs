//! A patch: one surface of the scene as the ray engine stores it (its "patch memory").

use crate::geometry::Polygon;

/// The shape of a patch. Bicubic Bezier patches join here (issue "Bezier").
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Shape {
    /// A planar convex quad or triangle.
    Polygon(Polygon),
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
    /// The polygon, for the planar shapes.
    pub fn as_polygon(&self) -> &Polygon {
        match &self.shape {
            Shape::Polygon(p) => p,
        }
    }
}
