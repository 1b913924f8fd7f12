//! Scene geometry as the kernel sees it: vectors, polygons and the patches built from them.

mod bezier;
mod polygon;
mod vec3;

pub use bezier::{Aabb, Bezier, BezierHit, BezierTree, Subdivision, TreeNode, MAX_DEPTH};
pub use polygon::{Polygon, PolygonError, UvFrame};
pub use vec3::Vec3;

/// The IEEE square root, correctly rounded, so the same bits everywhere: std's where the kernel
/// has std (hosts), which the compiler keeps in the instruction set it compiles for (a vector
/// instruction for eight lanes, a VEX-encoded one in AVX code); libm's elsewhere (boards).
/// libm's is a legacy-SSE `sqrtss` in inline assembly on x86-64: inside AVX-512 loops its
/// transitions tripled the time of the hosts' hemisphere set-up.
#[inline(always)]
pub(crate) fn sqrt(x: f32) -> f32 {
    #[cfg(feature = "std")]
    {
        x.sqrt()
    }
    #[cfg(not(feature = "std"))]
    {
        libm::sqrtf(x)
    }
}
