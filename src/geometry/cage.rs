//! Cage validation: a cage must be a closed, edge-manifold, consistently oriented
//! triangle mesh with no degenerate triangle, that does not cross itself, whose
//! parts (shells) are solids side by side or cavities inside them. Inward-facing
//! cages are flipped.

use super::intersect::ShellProblem;
use super::quads::{check_quad, find_quads, CageQuad, QuadSplit};
use super::{CageError, TriMesh};
use glam::DVec3;
use std::collections::HashMap;

/// A validated cage: closed, edge-manifold, outward-facing triangles. The fields
/// are private so that the only way to get one is [`Cage::new`], and every binder
/// can rely on these properties without checking them again.
#[derive(Clone, Debug, PartialEq)]
pub struct Cage {
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    /// For each triangle, the face of the file it came from.
    triangle_faces: Vec<u32>,
    /// The file's quads, as bilinear patches; each also has two of `triangles`.
    quads: Vec<CageQuad>,
    /// For each triangle, the index in `quads` of the quad it halves, or `NO_QUAD`.
    quad_of_triangle: Vec<u32>,
}

/// [`Cage::quad_of_triangle`]'s value for a triangle that is a face of its own.
const NO_QUAD: u32 = u32::MAX;

impl Cage {
    /// Validate `mesh` as a cage and return it outward-facing, with what validation
    /// noticed without rejecting it. See the module doc for the rules.
    pub fn new(mesh: TriMesh) -> Result<(Cage, CageReport), CageError> {
        validate(mesh)
    }

    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Vertex positions, in the file's `v` order (weights columns follow it).
    pub fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    /// Outward-facing triangles, in the order the file's faces were triangulated.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// For each triangle, the face of the file it came from (0-based).
    pub fn triangle_faces(&self) -> &[u32] {
        &self.triangle_faces
    }

    /// The file's quads, as bilinear patches (empty for a cage of triangles, and
    /// after [`Cage::split_quads`]).
    pub fn quads(&self) -> &[CageQuad] {
        &self.quads
    }

    pub fn has_quads(&self) -> bool {
        !self.quads.is_empty()
    }

    /// The quad (index into [`Cage::quads`]) that triangle `t` is half of, if any.
    #[inline]
    pub fn quad_of_triangle(&self, t: usize) -> Option<usize> {
        let quad = self.quad_of_triangle[t];
        (quad != NO_QUAD).then_some(quad as usize)
    }

    /// The triangles that are faces of their own, not halves of a quad: with
    /// [`Cage::quads`], the surface as the file drew it.
    pub fn lone_triangles(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.triangles.len()).filter(|&t| self.quad_of_triangle[t] == NO_QUAD)
    }

    /// The faces as polygons, in file order: each quad's four corners, and every
    /// other triangle on its own (a polygon of more than four corners comes back
    /// as its triangles). For writing the cage as the artist made it.
    pub fn polygons(&self) -> Vec<Vec<u32>> {
        let mut polygons = Vec::with_capacity(self.triangles.len());
        for (t, triangle) in self.triangles.iter().enumerate() {
            match self.quad_of_triangle(t) {
                Some(k) if self.quads[k].triangles[0] as usize == t => {
                    polygons.push(self.quads[k].corners.to_vec())
                }
                Some(_) => {}
                None => polygons.push(triangle.to_vec()),
            }
        }
        polygons
    }

    /// Corner positions of quad `k`.
    #[inline]
    pub fn quad(&self, k: usize) -> [DVec3; 4] {
        self.quads[k].corners.map(|i| self.positions[i as usize])
    }

    /// This cage with its quads split into triangles along `split`'s diagonal, and
    /// no quads: for families bound on triangles as they were before quads were
    /// patches. `QuadSplit::None` gives the cage as it is.
    pub fn split_quads(&self, split: QuadSplit) -> Cage {
        if split == QuadSplit::None || self.quads.is_empty() {
            return self.clone();
        }
        let mut triangles = self.triangles.clone();
        for quad in &self.quads {
            let halves = super::quads::split_quad(quad.corners, &self.positions, split);
            for (half, &t) in halves.into_iter().zip(&quad.triangles) {
                triangles[t as usize] = half;
            }
        }
        Cage {
            positions: self.positions.clone(),
            quad_of_triangle: vec![NO_QUAD; triangles.len()],
            triangles,
            triangle_faces: self.triangle_faces.clone(),
            quads: Vec::new(),
        }
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Corner positions of triangle `t`.
    #[inline]
    pub fn triangle(&self, t: usize) -> [DVec3; 3] {
        self.triangles[t].map(|i| self.positions[i as usize])
    }

    /// Triangle `t`'s outward unit normal (zero for a degenerate triangle).
    pub fn unit_normal(&self, t: usize) -> DVec3 {
        let [a, b, c] = self.triangle(t);
        (b - a).cross(c - a).normalize_or_zero()
    }

    /// Length of the bounding-box diagonal: the cage's size for relative tolerances.
    pub fn diagonal(&self) -> f64 {
        let (lo, hi) = super::bounds_of(&self.positions);
        (hi - lo).length()
    }

    /// Enclosed volume; positive for an outward-facing cage.
    pub fn signed_volume(&self) -> f64 {
        signed_volume(&self.positions, &self.triangles)
    }

    /// The same cage with other vertex positions (a pose), keeping its topology.
    /// Not validated again: a pose may fold the cage, and binding only ever uses
    /// the rest cage, which was.
    pub fn with_positions(&self, positions: Vec<DVec3>) -> Cage {
        assert_eq!(positions.len(), self.positions.len());
        Cage {
            positions,
            ..self.clone()
        }
    }
}

/// What validation noticed without rejecting the cage.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CageReport {
    /// All faces pointed inward and were reversed.
    pub flipped: bool,
    /// Vertices no face uses. They get zero weight everywhere.
    pub unreferenced: Vec<u32>,
    /// Enclosed volume after any flip (positive).
    pub volume: f64,
    /// Faces of more than four corners, split into triangles (a fan from their
    /// first corner); quads stay bilinear patches.
    pub split_polygons: usize,
}

impl CageReport {
    /// Human-readable notices and warnings, one per line.
    pub fn messages(&self) -> Vec<String> {
        let mut messages = Vec::new();
        if self.flipped {
            messages.push(
                "notice: the cage's faces pointed inward; they were flipped to face outward"
                    .to_owned(),
            );
        }
        if self.split_polygons > 0 {
            messages.push(format!(
                "notice: {} faces have more than four corners; each was split into a fan of triangles from its first corner",
                self.split_polygons
            ));
        }
        if !self.unreferenced.is_empty() {
            let shown: Vec<String> = self
                .unreferenced
                .iter()
                .take(8)
                .map(u32::to_string)
                .collect();
            let more = if self.unreferenced.len() > 8 {
                ", …"
            } else {
                ""
            };
            messages.push(format!(
                "warning: {} cage vertices are used by no face and get zero weight: {}{more}",
                self.unreferenced.len(),
                shown.join(", ")
            ));
        }
        messages
    }
}

/// Enclosed volume of closed `triangles`, positive when they face outward. The
/// tetrahedra are taken from the centre of the positions' bounding box, not from
/// the origin: far from the origin, products of absolute positions would round
/// away the volume (a 2.34-wide box at 1e7 came out inward).
pub(crate) fn signed_volume(positions: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    let (lo, hi) = super::bounds_of(positions);
    let centre = 0.5 * (lo + hi);
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize] - centre);
            a.dot(b.cross(c))
        })
        .sum::<f64>()
        / 6.0
}

fn validate(mesh: TriMesh) -> Result<(Cage, CageReport), CageError> {
    let count = mesh.positions.len();
    if count < 4 {
        return Err(CageError::TooFewVertices { count });
    }
    if let Some(vertex) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(CageError::NonFinite { vertex });
    }
    if mesh.triangles.is_empty() {
        return Err(CageError::NoFaces);
    }
    let face_of = |t: usize| mesh.triangle_faces.get(t).map_or(t, |&f| f as usize);
    for (t, triangle) in mesh.triangles.iter().enumerate() {
        if let Some(&index) = triangle.iter().find(|&&i| i as usize >= count) {
            return Err(CageError::IndexOutOfRange {
                face: face_of(t),
                index,
                count,
            });
        }
    }

    let diagonal = {
        let (lo, hi) = mesh.bounds();
        (hi - lo).length()
    };
    let (mut quads, split_polygons) = find_quads(&mesh);
    for quad in &quads {
        let corners = quad.corners.map(|i| mesh.positions[i as usize]);
        check_quad(&corners, quad.corners, quad.face as usize, diagonal)?;
    }
    for (t, &[a, b, c]) in mesh.triangles.iter().enumerate() {
        let [pa, pb, pc] = [a, b, c].map(|i| mesh.positions[i as usize]);
        let doubled_area = (pb - pa).cross(pc - pa).length();
        if a == b || b == c || a == c || doubled_area <= 1e-12 * diagonal * diagonal {
            return Err(CageError::DegenerateTriangle {
                face: face_of(t),
                a,
                b,
                c,
            });
        }
    }

    // Each undirected edge must be used by exactly two triangles, once in each direction.
    let mut edges: HashMap<(u32, u32), Vec<(usize, bool)>> =
        HashMap::with_capacity(mesh.triangles.len() * 2);
    for (t, triangle) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            let (from, to) = (triangle[k], triangle[(k + 1) % 3]);
            edges
                .entry((from.min(to), from.max(to)))
                .or_default()
                .push((t, from < to));
        }
    }
    let mut sorted_edges: Vec<_> = edges.into_iter().collect();
    sorted_edges.sort_unstable_by_key(|(edge, uses)| (uses.iter().map(|u| u.0).min(), *edge));
    for ((a, b), uses) in &sorted_edges {
        match uses.as_slice() {
            [(t, _)] => {
                return Err(CageError::OpenEdge {
                    a: *a,
                    b: *b,
                    face: face_of(*t),
                })
            }
            [(first, first_forward), (second, second_forward)] => {
                if first_forward == second_forward {
                    let (from, to) = if *first_forward { (*a, *b) } else { (*b, *a) };
                    return Err(CageError::InconsistentOrientation {
                        a: from,
                        b: to,
                        first: face_of(*first),
                        second: face_of(*second),
                    });
                }
            }
            _ => {
                let mut faces: Vec<usize> = uses.iter().map(|(t, _)| face_of(*t)).collect();
                faces.dedup();
                return Err(CageError::NonManifoldEdge {
                    a: *a,
                    b: *b,
                    count: uses.len(),
                    faces: faces
                        .iter()
                        .map(|face| (face + 1).to_string())
                        .collect::<Vec<_>>()
                        .join(", "),
                });
            }
        }
    }

    let mut triangles = mesh.triangles;
    let mut volume = signed_volume(&mesh.positions, &triangles);
    if volume.abs() <= 1e-12 * diagonal.powi(3) {
        return Err(CageError::ZeroVolume);
    }
    let flipped = volume < 0.0;
    if flipped {
        // Reversing the corner order makes a reversed copy of an outward cage identical to it.
        for triangle in &mut triangles {
            triangle.reverse();
        }
        for quad in &mut quads {
            quad.corners.reverse();
        }
        volume = -volume;
    }

    if let Some([first, second]) =
        super::quads::find_patch_crossing(&mesh.positions, &triangles, &quads, diagonal)
    {
        return Err(CageError::SelfIntersecting {
            first: face_of(first),
            second: face_of(second),
        });
    }
    match super::intersect::check_shells(&mesh.positions, &triangles) {
        None => {}
        Some(ShellProblem::Nested { inner, outer }) => {
            return Err(CageError::NestedShells {
                inner: face_of(inner),
                outer: face_of(outer),
            })
        }
        Some(ShellProblem::InwardAlone { shell }) => {
            return Err(CageError::InwardShell {
                shell: face_of(shell),
            })
        }
    }

    let mut referenced = vec![false; count];
    for triangle in &triangles {
        for &i in triangle {
            referenced[i as usize] = true;
        }
    }
    let unreferenced = (0..count as u32)
        .filter(|&i| !referenced[i as usize])
        .collect();
    let triangle_faces = if mesh.triangle_faces.len() == triangles.len() {
        mesh.triangle_faces
    } else {
        (0..triangles.len() as u32).collect()
    };
    let mut quad_of_triangle = vec![NO_QUAD; triangles.len()];
    for (k, quad) in quads.iter().enumerate() {
        for &t in &quad.triangles {
            quad_of_triangle[t as usize] = k as u32;
        }
    }
    Ok((
        Cage {
            positions: mesh.positions,
            triangles,
            triangle_faces,
            quads,
            quad_of_triangle,
        },
        CageReport {
            flipped,
            unreferenced,
            volume,
            split_polygons,
        },
    ))
}
