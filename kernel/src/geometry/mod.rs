//! Scene geometry as the kernel sees it: vectors, polygons and the patches built from them.

mod polygon;
mod vec3;

pub use polygon::{Polygon, PolygonError};
pub use vec3::Vec3;
