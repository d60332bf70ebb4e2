//! Why a mesh is not a cage. Every variant names the offending face, edge or
//! vertex, so that the message alone is enough to find the problem.

/// A mesh is not usable as a cage. The fields number faces from 0 in file order
/// (the n-th face line) and vertices from 0 in `v` order; the messages count both
/// from 1, as OBJ and the user do. The loaders add the file
/// ([`CageLoadError::Invalid`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CageError {
    #[error("a cage needs at least 4 vertices, this one has {count}")]
    TooFewVertices { count: usize },
    #[error("the cage has no faces")]
    NoFaces,
    #[error("face {} is a degenerate quad: corners {}, {}, {} are collinear (a quad needs four corners in general position)", .face + 1, .corners[0] + 1, .corners[1] + 1, .corners[2] + 1)]
    DegenerateQuad { face: usize, corners: [u32; 3] },
    #[error("face {} is a quad that folds over itself at corner {}: its bilinear patch turns its back on itself there (a bow tie, or a corner pushed through the opposite side)", .face + 1, .corner + 1)]
    FoldedQuad { face: usize, corner: u32 },
    #[error("vertex {} has a non-finite coordinate", .vertex + 1)]
    NonFinite { vertex: usize },
    #[error("face {} refers to vertex {}, but the cage has {count} vertices", .face + 1, *.index as u64 + 1)]
    IndexOutOfRange {
        face: usize,
        index: u32,
        count: usize,
    },
    #[error("face {} is degenerate (zero area) at vertices {}, {}, {}", .face + 1, .a + 1, .b + 1, .c + 1)]
    DegenerateTriangle { face: usize, a: u32, b: u32, c: u32 },
    #[error("the cage is not closed: edge {}–{} of face {} has no neighbouring face", .a + 1, .b + 1, .face + 1)]
    OpenEdge { a: u32, b: u32, face: usize },
    #[error("the cage is not edge-manifold: edge {}–{} is shared by {count} faces ({faces})", .a + 1, .b + 1)]
    NonManifoldEdge {
        a: u32,
        b: u32,
        count: usize,
        faces: String,
    },
    #[error("faces {} and {} are oriented inconsistently: both run along edge {}→{}", .first + 1, .second + 1, .a + 1, .b + 1)]
    InconsistentOrientation {
        a: u32,
        b: u32,
        first: usize,
        second: usize,
    },
    #[error("the cage encloses no volume")]
    ZeroVolume,
    #[error("the cage crosses itself: faces {} and {} intersect (a vertex pushed through a face, or a fold)", .first + 1, .second + 1)]
    SelfIntersecting { first: usize, second: usize },
    #[error("the cage's part with face {} lies inside its part with face {}, and both face outward: the space inside both would count twice", .inner + 1, .outer + 1)]
    NestedShells { inner: usize, outer: usize },
    #[error("the cage's part with face {} faces inward but is inside no other part, so it is not a cavity", .shell + 1)]
    InwardShell { shell: usize },
}
