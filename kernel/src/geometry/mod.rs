//! Scene geometry as the kernel sees it: vectors, polygons and the patches built from them.

mod bezier;
mod polygon;
mod vec3;

pub use bezier::{Aabb, Bezier, BezierHit, BezierTree, Subdivision, TreeNode, MAX_DEPTH};
pub use polygon::{Polygon, PolygonError, UvFrame};
pub use vec3::Vec3;
