//! Validation of a polygon soup and construction of the halfedge structure.
//!
//! The builder runs in linear time apart from sorting each vertex's few incident edges:
//!
//! 1. check sizes, coordinates, index ranges, repeated vertices and zero-area faces;
//! 2. group face sides into undirected edges with a counting sort keyed by the smaller
//!    endpoint (no hash map), finding non-manifold edges and duplicate faces on the way;
//! 3. orient each edge-connected component by a breadth-first search over face
//!    neighbours, flipping the minority of faces when the component is consistently
//!    orientable and failing when it is not;
//! 4. drop unreferenced vertices, create one boundary halfedge per boundary edge and link
//!    boundary loops, and check that the faces around every vertex form one fan.

use std::collections::HashMap;
use std::sync::atomic::{AtomicU32, Ordering};

use nalgebra::Point3;

use crate::mesh::{Mesh, MeshData};
use crate::parallel::in_turns;
use crate::vertex_map::NO_VERTEX;
use crate::{ComponentId, EdgeId, HalfedgeId, MeshError, PolygonSoup, VertexId, VertexMap};

const NONE: u32 = u32::MAX;

/// The largest coordinate magnitude the builder accepts.
///
/// Face areas are products of two coordinate differences, and the geometry downstream
/// (vector areas, squared norms of cross products, Gram determinants of the element
/// maps) takes products of four: with every |coordinate| <= 1e75 a difference is at most
/// 2e75 and a product of four at most about 1e302, below `f64::MAX` (about 1.8e308).
pub const MAX_COORDINATE: f64 = 1e75;

/// The smallest bounding-box diagonal the builder accepts for vertices that do not all
/// coincide.
///
/// The mirror of [`MAX_COORDINATE`]: a product of four lengths of at least 1e-75 is at
/// least 1e-300, above the smallest normal `f64` (about 2.2e-308), so areas and their
/// squares do not round to zero.
pub const MIN_EXTENT: f64 = 1e-75;

/// The fewest bits of a coordinate that must resolve the mesh's extent: the spacing of
/// `f64` values at the largest coordinate magnitude `m` (`m 2^-52`) must be at most
/// `2^-PRECISION_BITS` of the bounding-box diagonal. A mesh far from the origin against
/// its size (a unit disk translated by 1e15 has coordinates 0.125 apart) has vertices
/// rounded onto one another and faces folded by rounding alone.
pub const PRECISION_BITS: i32 = 26;

/// What the builder may repair instead of failing. Nothing is repaired unless asked, and
/// everything repaired is listed in the [`BuildReport`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Repair {
    /// Drop faces with a repeated vertex or an area at most the degeneracy threshold.
    pub drop_degenerate_faces: bool,
    /// Drop faces whose vertex set equals that of an earlier face (the later one goes).
    pub drop_duplicate_faces: bool,
    /// Merge vertices with bit-identical positions into the first of them.
    pub merge_coincident_vertices: bool,
}

impl Repair {
    /// Repair nothing: every defect is an error.
    pub const NONE: Repair = Repair {
        drop_degenerate_faces: false,
        drop_duplicate_faces: false,
        merge_coincident_vertices: false,
    };
    /// Every safe repair.
    pub const ALL: Repair = Repair {
        drop_degenerate_faces: true,
        drop_duplicate_faces: true,
        merge_coincident_vertices: true,
    };
}

/// Options of [`Mesh::build`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BuildOptions {
    /// A face is degenerate when its area is at most
    /// `degenerate_area_tolerance * d^2`, with `d` the bounding-box diagonal of the
    /// vertices the faces use (an unreferenced vertex far away changes nothing). Default
    /// `1e-12`. A negative value (down to minus infinity) accepts
    /// every face, even one of zero area (for meshes whose faces were validated before);
    /// NaN and plus infinity are refused ([`MeshError::InvalidTolerance`]).
    pub degenerate_area_tolerance: f64,
    /// What to repair instead of failing. Default: nothing.
    pub repair: Repair,
}

impl Default for BuildOptions {
    fn default() -> Self {
        Self {
            degenerate_area_tolerance: 1e-12,
            repair: Repair::NONE,
        }
    }
}

/// What the builder changed on its way from the soup to the mesh. All face and vertex
/// indices here are input indices.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BuildReport {
    /// Faces whose vertex order was reversed to orient their component consistently.
    pub faces_reoriented: usize,
    /// Input vertices that no face uses (left out of the mesh).
    pub unreferenced_vertices: Vec<usize>,
    /// Faces dropped as degenerate (repair).
    pub dropped_degenerate_faces: Vec<usize>,
    /// Faces dropped as duplicates of an earlier face (repair).
    pub dropped_duplicate_faces: Vec<usize>,
    /// Vertices merged into an earlier vertex at the same position, as
    /// `(merged, kept)` (repair).
    pub merged_vertices: Vec<(usize, usize)>,
    /// The absolute area threshold used for degenerate faces.
    pub degenerate_area_threshold: f64,
}

impl BuildReport {
    /// True if any repair changed the input.
    pub fn repaired(&self) -> bool {
        !(self.dropped_degenerate_faces.is_empty()
            && self.dropped_duplicate_faces.is_empty()
            && self.merged_vertices.is_empty())
    }
}

/// Faces as the builder works on them: flat vertex indices (input numbering, after
/// merging) with offsets, and each face's input index.
struct WorkFaces {
    indices: Vec<u32>,
    offsets: Vec<u32>,
    input: Vec<u32>,
}

impl WorkFaces {
    fn len(&self) -> usize {
        self.input.len()
    }

    fn face(&self, f: usize) -> &[u32] {
        &self.indices[self.offsets[f] as usize..self.offsets[f + 1] as usize]
    }

    fn retain(&mut self, keep: impl Fn(usize) -> bool) {
        let mut out = WorkFaces {
            indices: Vec::with_capacity(self.indices.len()),
            offsets: Vec::with_capacity(self.offsets.len()),
            input: Vec::with_capacity(self.input.len()),
        };
        out.offsets.push(0);
        for f in 0..self.len() {
            if keep(f) {
                out.indices.extend_from_slice(self.face(f));
                out.offsets.push(out.indices.len() as u32);
                out.input.push(self.input[f]);
            }
        }
        *self = out;
    }

    /// Reverses face `f` keeping its first vertex: (v0, v1, .., vn) -> (v0, vn, .., v1).
    fn reverse(&mut self, f: usize) {
        let (a, b) = (self.offsets[f] as usize, self.offsets[f + 1] as usize);
        self.indices[a + 1..b].reverse();
    }
}

/// Sorted vertex set of a face, padded, for duplicate detection.
fn vertex_set(face: &[u32]) -> [u32; 4] {
    let mut key = [NONE; 4];
    key[..face.len()].copy_from_slice(face);
    key.sort_unstable();
    key
}

/// Norm of the polygon vector area: half the cross product of the diagonals for a quad,
/// half the cross product of two sides for a triangle.
fn polygon_area(p: &[Point3<f64>], face: &[u32]) -> f64 {
    let at = |k: usize| p[face[k] as usize];
    let twice = if face.len() == 3 {
        (at(1) - at(0)).cross(&(at(2) - at(0)))
    } else {
        (at(2) - at(0)).cross(&(at(3) - at(1)))
    };
    0.5 * twice.norm()
}

/// The first corner of a quad at which its bilinear patch folds, or `None`.
///
/// The patch `x(u, v)` of corners `p0..p3` has the normal `x_u x x_v`, bilinear in
/// `(u, v)`, so its component along the quad's vector area `N = (p2 - p0) x (p3 - p1)` is
/// positive on the whole patch exactly when it is positive at the four corners, where it
/// is `((p_{k+1} - p_k) x (p_{k-1} - p_k)) . N`. A planar quad folds exactly when it is
/// concave (a dart) or self-crossing (a bow tie); a non-planar one when it is so seen
/// along `N` (however sharply it is bent across a diagonal otherwise: a square bent by
/// 120 degrees does not fold). A straight corner (a vertex on the line of its two
/// neighbours) makes the normal vanish there only, and is kept. A patch that folds turns
/// over inside the face: its area, Jacobian and Beltrami coefficient have no consistent
/// sign, and every measure of it disagrees with another.
fn folded_quad_corner(p: &[Point3<f64>], face: &[u32]) -> Option<usize> {
    let at = |k: usize| p[face[k % 4] as usize];
    let normal = (at(2) - at(0)).cross(&(at(3) - at(1)));
    (0..4).find(|&k| {
        let corner = (at(k + 1) - at(k)).cross(&(at(k + 3) - at(k)));
        corner.dot(&normal) < 0.0
    })
}

/// Undirected edges of the work faces.
struct EdgeGroups {
    /// Edge of each corner (corner `c` is the side from vertex `c` to the next vertex).
    corner_edge: Vec<u32>,
    /// The other corner on the same edge, or `NONE` on a boundary edge.
    corner_twin: Vec<u32>,
    edge_count: usize,
}

/// Result of grouping: either the edge groups or duplicate pairs `(later, earlier)` in
/// work-face indices, which must be removed before grouping again.
enum Grouping {
    Edges(EdgeGroups),
    Duplicates(Vec<(usize, usize)>),
}

fn corner_faces(faces: &WorkFaces) -> (Vec<u32>, Vec<u32>) {
    let nc = faces.indices.len();
    let mut corner_face = vec![0u32; nc];
    let mut next_corner = vec![0u32; nc];
    for f in 0..faces.len() {
        let (a, b) = (faces.offsets[f], faces.offsets[f + 1]);
        for c in a..b {
            corner_face[c as usize] = f as u32;
            next_corner[c as usize] = if c + 1 == b { a } else { c + 1 };
        }
    }
    (corner_face, next_corner)
}

/// The side of each corner as an undirected edge key: corner `c` runs from vertex
/// `indices[c]` to vertex `indices[next_corner[c]]`.
#[derive(Clone, Copy)]
struct CornerSides<'a> {
    indices: &'a [u32],
    next_corner: &'a [u32],
}

impl CornerSides<'_> {
    /// The endpoints of corner `c`'s side as `(smaller, larger)`.
    fn ends(&self, c: usize) -> (u32, u32) {
        let (u, w) = (self.indices[c], self.indices[self.next_corner[c] as usize]);
        (u.min(w), u.max(w))
    }

    /// The larger endpoint of corner `c`'s side: the key within a bucket.
    fn hi(&self, c: &u32) -> u32 {
        self.ends(*c as usize).1
    }
}

/// Counting sort of the corners by their side's smaller endpoint: returns `start` (the
/// first position of vertex `v`'s bucket is `start[v]`, `start[vertex_count]` is the
/// corner count) and the corners in bucket order, each bucket in corner order.
fn corners_by_low_end(sides: CornerSides, vertex_count: usize) -> (Vec<u32>, Vec<u32>) {
    let nc = sides.indices.len();
    let mut start = vec![0u32; vertex_count + 1];
    for c in 0..nc {
        start[sides.ends(c).0 as usize + 1] += 1;
    }
    for v in 0..vertex_count {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut by_lo = vec![0u32; nc];
    for c in 0..nc {
        let lo = sides.ends(c).0 as usize;
        by_lo[fill[lo] as usize] = c as u32;
        fill[lo] += 1;
    }
    (start, by_lo)
}

/// Where [`match_edge_group`] records its findings: the twin of each corner (atomics, as
/// the vertex ranges are matched on several threads, each writing only its own corners)
/// and the duplicate face pairs found so far in the range.
struct TwinMatches<'a> {
    corner_twin: &'a [AtomicU32],
    duplicates: Vec<(usize, usize)>,
}

/// Matches the corners of one edge (a group of corners with the same side, at least one):
/// faces with equal vertex sets on it are recorded as duplicates `(later, earlier)`;
/// without duplicates, two corners become twins and more than two make the edge
/// non-manifold (the error names the edge's input faces in increasing order).
fn match_edge_group(
    group: &[u32],
    faces: &WorkFaces,
    corner_face: &[u32],
    sides: CornerSides,
    matches: &mut TwinMatches,
) -> Result<(), MeshError> {
    if group.len() == 1 {
        return Ok(());
    }
    let mut found_duplicate = false;
    for (i, &a) in group.iter().enumerate() {
        let fa = corner_face[a as usize] as usize;
        for &b in &group[i + 1..] {
            let fb = corner_face[b as usize] as usize;
            if vertex_set(faces.face(fa)) == vertex_set(faces.face(fb)) {
                found_duplicate = true;
                matches.duplicates.push((fa.max(fb), fa.min(fb)));
            }
        }
    }
    if found_duplicate {
        return Ok(());
    }
    if group.len() > 2 {
        let (a, b) = sides.ends(group[0] as usize);
        let mut on_edge: Vec<usize> = group
            .iter()
            .map(|&c| faces.input[corner_face[c as usize] as usize] as usize)
            .collect();
        on_edge.sort_unstable();
        return Err(MeshError::NonManifoldEdge {
            a: a as usize,
            b: b as usize,
            faces: on_edge,
        });
    }
    matches.corner_twin[group[0] as usize].store(group[1], Ordering::Relaxed);
    matches.corner_twin[group[1] as usize].store(group[0], Ordering::Relaxed);
    Ok(())
}

/// Groups the corners of the work faces into undirected edges (bucketed by their smaller
/// endpoint, sorted by the larger), or returns the duplicate face pairs found; fails on
/// the first non-manifold edge in vertex order.
fn group_edges(
    faces: &WorkFaces,
    corner_face: &[u32],
    next_corner: &[u32],
    vertex_count: usize,
) -> Result<Grouping, MeshError> {
    let sides = CornerSides {
        indices: &faces.indices,
        next_corner,
    };
    let nc = faces.indices.len();
    let (start, mut by_lo) = corners_by_low_end(sides, vertex_count);

    // The buckets in ranges of vertices, one per thread (sorting them and matching their
    // corners is most of the grouping): first each range's buckets sorted and its edges
    // counted, then its edges numbered after the earlier ranges' and its corners
    // matched. Each corner is in one bucket, so the ranges write disjoint corners.
    let ranges = bucket_ranges(&start, vertex_count, nc);
    let mut parts: Vec<(std::ops::Range<usize>, &mut [u32])> = Vec::with_capacity(ranges.len());
    let mut rest = by_lo.as_mut_slice();
    for range in &ranges {
        let (part, tail) = rest.split_at_mut((start[range.end] - start[range.start]) as usize);
        parts.push((range.clone(), part));
        rest = tail;
    }
    let by_hi = |c: &u32| sides.hi(c);
    let threads = parts.len();
    let counts = in_turns(parts.iter_mut().collect(), threads, |(range, part)| {
        let base = start[range.start] as usize;
        let mut edges = 0;
        for v in range.clone() {
            let bucket = &mut part[start[v] as usize - base..start[v + 1] as usize - base];
            bucket.sort_unstable_by_key(by_hi);
            edges += bucket.chunk_by(|a, b| by_hi(a) == by_hi(b)).count();
        }
        edges
    });
    let corner_edge: Vec<AtomicU32> = (0..nc).map(|_| AtomicU32::new(NONE)).collect();
    let corner_twin: Vec<AtomicU32> = (0..nc).map(|_| AtomicU32::new(NONE)).collect();
    let mut first_edge = Vec::with_capacity(counts.len());
    let mut edge_count = 0usize;
    for count in &counts {
        first_edge.push(edge_count);
        edge_count += count;
    }
    let mut numbered: Vec<_> = parts.into_iter().zip(first_edge).collect();
    let matched = in_turns(
        numbered.iter_mut().collect(),
        threads,
        |((range, part), first)| {
            let base = start[range.start] as usize;
            let mut e = *first as u32;
            let mut matches = TwinMatches {
                corner_twin: &corner_twin,
                duplicates: Vec::new(),
            };
            for v in range.clone() {
                let bucket = &part[start[v] as usize - base..start[v + 1] as usize - base];
                for group in bucket.chunk_by(|a, b| by_hi(a) == by_hi(b)) {
                    for &c in group {
                        corner_edge[c as usize].store(e, Ordering::Relaxed);
                    }
                    e += 1;
                    match_edge_group(group, faces, corner_face, sides, &mut matches)?;
                }
            }
            Ok(matches.duplicates)
        },
    );
    // The first non-manifold edge in vertex order, as one pass over the buckets finds.
    let mut duplicates = Vec::new();
    for part in matched {
        duplicates.extend(part?);
    }
    if duplicates.is_empty() {
        Ok(Grouping::Edges(EdgeGroups {
            corner_edge: corner_edge.into_iter().map(AtomicU32::into_inner).collect(),
            corner_twin: corner_twin.into_iter().map(AtomicU32::into_inner).collect(),
            edge_count,
        }))
    } else {
        duplicates.sort_unstable();
        duplicates.dedup();
        Ok(Grouping::Duplicates(duplicates))
    }
}

/// Corners from which [`group_edges`] matches buckets on several threads.
const PARALLEL_GROUPING_FROM: usize = 1 << 16;

/// Consecutive ranges of the vertices `0..vertex_count`, one per thread (one below
/// [`PARALLEL_GROUPING_FROM`] corners), holding about as many corners each: `start[v]`
/// is the first corner of vertex `v`'s bucket.
fn bucket_ranges(
    start: &[u32],
    vertex_count: usize,
    corners: usize,
) -> Vec<std::ops::Range<usize>> {
    let threads = if corners < PARALLEL_GROUPING_FROM {
        1
    } else {
        crate::parallel::available_threads()
    };
    let mut ranges = Vec::with_capacity(threads);
    let mut begin = 0;
    for k in 1..threads {
        let target = (k * corners / threads) as u32;
        let end = start[..=vertex_count]
            .partition_point(|&s| s < target)
            .clamp(begin, vertex_count);
        ranges.push(begin..end);
        begin = end;
    }
    ranges.push(begin..vertex_count);
    ranges
}

/// Orientation of every face relative to its component's majority, and components.
struct Orientation {
    flip: Vec<bool>,
    face_component: Vec<u32>,
    component_count: usize,
}

/// Breadth-first search over face neighbours: across an edge, two faces agree when they
/// traverse it in opposite directions. Each component keeps the orientation of the
/// majority of its faces.
fn orient(
    faces: &WorkFaces,
    groups: &EdgeGroups,
    corner_face: &[u32],
) -> Result<Orientation, MeshError> {
    const UNSEEN: u8 = 2;
    let nf = faces.len();
    let idx = &faces.indices;
    let mut state = vec![UNSEEN; nf];
    let mut face_component = vec![0u32; nf];
    let mut queue: Vec<u32> = Vec::with_capacity(nf);
    let mut component_count = 0usize;
    for seed in 0..nf {
        if state[seed] != UNSEEN {
            continue;
        }
        let first = queue.len();
        state[seed] = 0;
        queue.push(seed as u32);
        let mut head = first;
        while head < queue.len() {
            let f = queue[head] as usize;
            head += 1;
            face_component[f] = component_count as u32;
            for c in faces.offsets[f]..faces.offsets[f + 1] {
                let t = groups.corner_twin[c as usize];
                if t == NONE {
                    continue;
                }
                let g = corner_face[t as usize] as usize;
                let same_direction = idx[c as usize] == idx[t as usize];
                let want = state[f] ^ u8::from(same_direction);
                if state[g] == UNSEEN {
                    state[g] = want;
                    queue.push(g as u32);
                } else if state[g] != want {
                    let (a, b) = (idx[c as usize], idx[t as usize]);
                    let (a, b) = if same_direction {
                        let n = faces.face(f);
                        let k = c as usize - faces.offsets[f] as usize;
                        (n[k], n[(k + 1) % n.len()])
                    } else {
                        (a, b)
                    };
                    return Err(MeshError::NonOrientable {
                        face: faces.input[f] as usize,
                        neighbor: faces.input[g] as usize,
                        a: a.min(b) as usize,
                        b: a.max(b) as usize,
                    });
                }
            }
        }
        let members = &queue[first..];
        let flipped = members.iter().filter(|&&f| state[f as usize] == 1).count();
        if 2 * flipped > members.len() {
            for &f in members {
                state[f as usize] ^= 1;
            }
        }
        component_count += 1;
    }
    Ok(Orientation {
        flip: state.iter().map(|&s| s == 1).collect(),
        face_component,
        component_count,
    })
}

/// For each vertex, the first vertex with a bit-identical position (itself if none).
fn coincident_representatives(positions: &[Point3<f64>]) -> Vec<u32> {
    let mut first: HashMap<[u64; 3], u32> = HashMap::with_capacity(positions.len());
    positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            // Adding 0.0 turns -0.0 into +0.0 so both land on the same key.
            let key = [
                (p.x + 0.0).to_bits(),
                (p.y + 0.0).to_bits(),
                (p.z + 0.0).to_bits(),
            ];
            *first.entry(key).or_insert(i as u32)
        })
        .collect()
}

/// Fails when a coordinate exceeds [`MAX_COORDINATE`] in magnitude (naming the first such
/// vertex), when the vertices, not all at one point, span less than [`MIN_EXTENT`], or
/// when their coordinates resolve the span to fewer than [`PRECISION_BITS`] bits.
/// All vertices count, used or not: a coordinate out of range is refused wherever it is.
fn check_range(positions: &[Point3<f64>]) -> Result<(), MeshError> {
    for (vertex, p) in positions.iter().enumerate() {
        let value = [p.x, p.y, p.z]
            .into_iter()
            .fold(0.0_f64, |a, c| if c.abs() > a.abs() { c } else { a });
        if value.abs() > MAX_COORDINATE {
            return Err(MeshError::CoordinateOverflow {
                vertex,
                value,
                max: MAX_COORDINATE,
            });
        }
    }
    // hypot, not the square root of a sum of squares: the squares of a tiny extent
    // underflow to zero, which is the very thing to detect.
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let extent = |k: usize| (hi[k] - lo[k]).max(0.0);
    let diagonal = extent(0).hypot(extent(1)).hypot(extent(2));
    if diagonal > 0.0 && diagonal < MIN_EXTENT {
        return Err(MeshError::ExtentUnderflow {
            diagonal,
            min: MIN_EXTENT,
        });
    }
    let magnitude = (0..3)
        .map(|k| lo[k].abs().max(hi[k].abs()))
        .fold(0.0, f64::max);
    let spacing = magnitude * f64::EPSILON;
    if diagonal > 0.0 && spacing > diagonal * 2f64.powi(-PRECISION_BITS) {
        return Err(MeshError::PrecisionLoss {
            diagonal,
            magnitude,
            spacing,
        });
    }
    Ok(())
}

/// The squared bounding-box diagonal of the vertices the faces use (indices out of range
/// are left to the face checks): an unreferenced vertex far away must not make every face
/// degenerate. 0 when no face uses a vertex.
fn squared_bbox_diagonal(soup: &PolygonSoup) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &i in soup.faces().flatten() {
        if let Some(p) = soup.positions.get(i as usize) {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    (0..3).map(|k| (hi[k] - lo[k]).max(0.0).powi(2)).sum()
}

/// Checks every face and copies the valid ones (through the vertex representatives) into
/// the working face list; drops degenerate faces when repairing.
fn collect_faces(
    soup: &PolygonSoup,
    representative: Option<&[u32]>,
    threshold: f64,
    repair: Repair,
    report: &mut BuildReport,
) -> Result<WorkFaces, MeshError> {
    let nv = soup.vertex_count();
    let mut faces = WorkFaces {
        indices: Vec::with_capacity(soup.face_count() * 3),
        offsets: Vec::with_capacity(soup.face_count() + 1),
        input: Vec::with_capacity(soup.face_count()),
    };
    faces.offsets.push(0);
    let mut buf = [0u32; 4];
    for (fi, face) in soup.faces().enumerate() {
        if !(3..=4).contains(&face.len()) {
            return Err(MeshError::UnsupportedFaceSize {
                face: fi,
                size: face.len(),
            });
        }
        for (k, &v) in face.iter().enumerate() {
            if v as usize >= nv {
                return Err(MeshError::VertexIndexOutOfRange {
                    face: fi,
                    index: v as usize,
                    vertex_count: nv,
                });
            }
            buf[k] = representative.map_or(v, |r| r[v as usize]);
        }
        let mapped = &buf[..face.len()];
        let repeated = (1..mapped.len()).find(|&k| mapped[..k].contains(&mapped[k]));
        if let Some(k) = repeated {
            if repair.drop_degenerate_faces {
                report.dropped_degenerate_faces.push(fi);
                continue;
            }
            return Err(MeshError::RepeatedVertex {
                face: fi,
                vertex: face[k] as usize,
            });
        }
        let area = polygon_area(&soup.positions, mapped);
        if area <= threshold {
            if repair.drop_degenerate_faces {
                report.dropped_degenerate_faces.push(fi);
                continue;
            }
            return Err(MeshError::DegenerateFace {
                face: fi,
                area,
                threshold,
            });
        }
        if mapped.len() == 4
            && let Some(k) = folded_quad_corner(&soup.positions, mapped)
        {
            return Err(MeshError::FoldedQuad {
                face: fi,
                vertex: face[k] as usize,
            });
        }
        faces.indices.extend_from_slice(mapped);
        faces.offsets.push(faces.indices.len() as u32);
        faces.input.push(fi as u32);
    }
    Ok(faces)
}

pub(crate) fn build(
    soup: &PolygonSoup,
    options: &BuildOptions,
) -> Result<(Mesh, BuildReport), MeshError> {
    let nv = soup.vertex_count();
    if nv >= NONE as usize {
        return Err(MeshError::TooLarge { what: "vertices" });
    }
    // Four corners per face plus as many boundary halfedges must fit in u32.
    if soup.face_count() >= (NONE as usize) / 8 {
        return Err(MeshError::TooLarge { what: "faces" });
    }
    if soup.face_count() == 0 {
        return Err(MeshError::NoFaces);
    }
    if let Some((i, p)) = soup
        .positions
        .iter()
        .enumerate()
        .find(|(_, p)| !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()))
    {
        return Err(MeshError::NonFiniteCoordinate {
            vertex: i,
            x: p.x,
            y: p.y,
            z: p.z,
        });
    }

    let tolerance = options.degenerate_area_tolerance;
    if tolerance.is_nan() || tolerance == f64::INFINITY {
        return Err(MeshError::InvalidTolerance { value: tolerance });
    }
    check_range(&soup.positions)?;

    let repair = options.repair;
    let threshold = options.degenerate_area_tolerance * squared_bbox_diagonal(soup);
    let mut report = BuildReport {
        degenerate_area_threshold: threshold,
        ..BuildReport::default()
    };
    let representative = repair
        .merge_coincident_vertices
        .then(|| coincident_representatives(&soup.positions));

    let faces = collect_faces(
        soup,
        representative.as_deref(),
        threshold,
        repair,
        &mut report,
    )?;
    let oriented = group_and_orient(faces, nv, repair, &mut report)?;
    report.dropped_degenerate_faces.sort_unstable();
    report.dropped_duplicate_faces.sort_unstable();

    assemble(soup, oriented, representative.as_deref(), report)
}

/// Work faces grouped into edges and consistently oriented: what [`assemble`] builds the
/// halfedge arrays from.
struct OrientedFaces {
    faces: WorkFaces,
    groups: EdgeGroups,
    orientation: Orientation,
    /// Face of each corner.
    corner_face: Vec<u32>,
    /// The next corner around its face of each corner.
    next_corner: Vec<u32>,
}

/// Groups the faces' sides into edges and orients every component, until a pass finds
/// nothing to change: duplicate faces are dropped (when repairing; otherwise the first
/// pair is the error) and the grouping redone; reversed faces are flipped and the
/// grouping redone, whose orientation then flips nothing.
fn group_and_orient(
    mut faces: WorkFaces,
    vertex_count: usize,
    repair: Repair,
    report: &mut BuildReport,
) -> Result<OrientedFaces, MeshError> {
    loop {
        if faces.len() == 0 {
            return Err(MeshError::NoFaces);
        }
        let (corner_face, next_corner) = corner_faces(&faces);
        let groups = match group_edges(&faces, &corner_face, &next_corner, vertex_count)? {
            Grouping::Edges(groups) => groups,
            Grouping::Duplicates(pairs) => {
                if !repair.drop_duplicate_faces {
                    let (later, earlier) = pairs[0];
                    return Err(MeshError::DuplicateFace {
                        face: faces.input[later] as usize,
                        first: faces.input[earlier] as usize,
                    });
                }
                let mut drop = vec![false; faces.len()];
                for &(later, _) in &pairs {
                    drop[later] = true;
                }
                report.dropped_duplicate_faces.extend(
                    (0..faces.len())
                        .filter(|&f| drop[f])
                        .map(|f| faces.input[f] as usize),
                );
                faces.retain(|f| !drop[f]);
                continue;
            }
        };
        let orientation = orient(&faces, &groups, &corner_face)?;
        let flips = orientation.flip.iter().filter(|&&f| f).count();
        if flips == 0 {
            return Ok(OrientedFaces {
                faces,
                groups,
                orientation,
                corner_face,
                next_corner,
            });
        }
        report.faces_reoriented += flips;
        for (f, &flip) in orientation.flip.iter().enumerate() {
            if flip {
                faces.reverse(f);
            }
        }
    }
}

/// The mesh's vertices: the input vertices the faces use, in input order.
struct CompactVertices {
    /// Mesh index of each input vertex (`NO_VERTEX` when no face uses it).
    new_id: Vec<u32>,
    /// Input index of each mesh vertex.
    to_input: Vec<u32>,
    /// Mesh index of each input vertex through its representative when merging.
    from_input: Vec<u32>,
    /// Position of each mesh vertex.
    positions: Vec<Point3<f64>>,
    /// The input vertices no face uses, with their positions.
    unreferenced: Vec<(u32, Point3<f64>)>,
}

/// Compacts the vertices, keeping the input's relative order, and records merged and
/// unreferenced vertices in the report.
fn compact_vertices(
    soup: &PolygonSoup,
    faces: &WorkFaces,
    representative: Option<&[u32]>,
    report: &mut BuildReport,
) -> CompactVertices {
    let nv_in = soup.vertex_count();
    let mut referenced = vec![false; nv_in];
    for &v in &faces.indices {
        referenced[v as usize] = true;
    }
    let mut new_id = vec![NO_VERTEX; nv_in];
    let mut to_input = Vec::with_capacity(nv_in);
    let mut positions = Vec::with_capacity(nv_in);
    let mut unreferenced = Vec::new();
    for i in 0..nv_in {
        // A vertex merged into a vertex that faces use is part of the mesh; one merged
        // into an unreferenced vertex is just as unreferenced.
        let merged_into = representative
            .map(|r| r[i] as usize)
            .filter(|&r| r != i && referenced[r]);
        if referenced[i] {
            new_id[i] = to_input.len() as u32;
            to_input.push(i as u32);
            positions.push(soup.positions[i]);
        } else if let Some(r) = merged_into {
            report.merged_vertices.push((i, r));
        } else {
            unreferenced.push((i as u32, soup.positions[i]));
            report.unreferenced_vertices.push(i);
        }
    }
    let from_input: Vec<u32> = match representative {
        Some(r) => (0..nv_in).map(|i| new_id[r[i] as usize]).collect(),
        None => new_id.clone(),
    };
    CompactVertices {
        new_id,
        to_input,
        from_input,
        positions,
        unreferenced,
    }
}

/// Halfedge connectivity as [`assemble`] builds it: the face corners are the interior
/// halfedges `0..interior`, the boundary halfedges follow them.
struct HalfedgeArrays {
    origin: Vec<u32>,
    next: Vec<u32>,
    prev: Vec<u32>,
    twin: Vec<u32>,
    edge: Vec<u32>,
    /// The number of interior halfedges (face corners).
    interior: usize,
}

impl HalfedgeArrays {
    /// The interior halfedges of the oriented faces (`next` is `next_corner`), with
    /// `prev` already sized for the boundary halfedges to come (one per corner without
    /// a twin).
    fn interior(
        faces: &WorkFaces,
        next_corner: Vec<u32>,
        groups: EdgeGroups,
        new_id: &[u32],
    ) -> Self {
        let nc = faces.indices.len();
        let boundary_count = groups.corner_twin.iter().filter(|&&t| t == NONE).count();
        let nh = nc + boundary_count;
        let mut origin = Vec::with_capacity(nh);
        origin.extend(faces.indices.iter().map(|&v| new_id[v as usize]));
        let next = next_corner;
        let mut prev = vec![0u32; nh];
        for c in 0..nc {
            prev[next[c] as usize] = c as u32;
        }
        HalfedgeArrays {
            origin,
            next,
            prev,
            twin: groups.corner_twin,
            edge: groups.corner_edge,
            interior: nc,
        }
    }

    /// Creates one boundary halfedge opposite each corner without a twin and links the
    /// boundary halfedges into loops; returns the outgoing boundary halfedge of each of
    /// the `vertex_count` vertices (`NONE` for interior vertices). Fails on a vertex with
    /// two outgoing boundary halfedges or an incoming one without an outgoing one.
    fn add_boundary(
        &mut self,
        vertex_count: usize,
        to_input: &[u32],
    ) -> Result<Vec<u32>, MeshError> {
        let nc = self.interior;
        let nh = self.prev.len();
        let mut out_boundary = vec![NONE; vertex_count];
        for c in 0..nc {
            if self.twin[c] != NONE {
                continue;
            }
            let b = self.origin.len() as u32;
            let w = self.origin[self.next[c] as usize];
            if out_boundary[w as usize] != NONE {
                return Err(self.non_manifold_vertex(to_input, w));
            }
            out_boundary[w as usize] = b;
            self.origin.push(w);
            self.twin[c] = b;
            self.twin.push(c as u32);
            self.edge.push(self.edge[c]);
        }
        self.next.resize(nh, NONE);
        for b in nc..nh {
            // Boundary halfedge b runs from target(c) back to origin(c).
            let u = self.origin[self.twin[b] as usize];
            let nb = out_boundary[u as usize];
            if nb == NONE {
                return Err(self.non_manifold_vertex(to_input, u));
            }
            self.next[b] = nb;
            self.prev[nb as usize] = b as u32;
        }
        Ok(out_boundary)
    }

    /// Outgoing halfedge per vertex: the boundary one on the boundary, so that
    /// circulating from it visits the fan of faces in order.
    fn vertex_halfedges(&self, out_boundary: &[u32]) -> Vec<u32> {
        let nv = out_boundary.len();
        let mut vertex_halfedge = vec![NONE; nv];
        for c in 0..self.interior {
            vertex_halfedge[self.origin[c] as usize] = c as u32;
        }
        for v in 0..nv {
            if out_boundary[v] != NONE {
                vertex_halfedge[v] = out_boundary[v];
            }
        }
        vertex_halfedge
    }

    /// Checks for one fan per vertex: circulating (`h -> twin(prev(h))`) from the
    /// vertex's halfedge must visit every outgoing halfedge.
    fn check_fans(&self, vertex_halfedge: &[u32], to_input: &[u32]) -> Result<(), MeshError> {
        let nv = vertex_halfedge.len();
        let mut degree = vec![0u32; nv];
        for &o in &self.origin {
            degree[o as usize] += 1;
        }
        for v in 0..nv {
            let start = vertex_halfedge[v];
            let mut h = start;
            let mut count = 0u32;
            loop {
                count += 1;
                h = self.twin[self.prev[h as usize] as usize];
                if h == start || count > degree[v] {
                    break;
                }
            }
            if count != degree[v] {
                return Err(self.non_manifold_vertex(to_input, v as u32));
            }
        }
        Ok(())
    }

    /// The error for mesh vertex `v`: see [`non_manifold_vertex`].
    fn non_manifold_vertex(&self, to_input: &[u32], v: u32) -> MeshError {
        non_manifold_vertex(
            self.interior,
            &self.origin,
            &self.twin,
            &self.prev,
            to_input,
            v,
        )
    }
}

/// The face or boundary loop of every halfedge: corner `c` keeps its face, boundary
/// halfedges get loop ids `face_count, face_count + 1, ..` in order of each loop's first
/// boundary halfedge. Returns it with each loop's first halfedge.
fn boundary_loops(
    corner_face: Vec<u32>,
    next: &[u32],
    face_count: usize,
) -> (Vec<u32>, Vec<HalfedgeId>) {
    let (nc, nh) = (corner_face.len(), next.len());
    let mut face_or_loop = corner_face;
    let mut loop_halfedge = Vec::new();
    face_or_loop.resize(nh, NONE);
    for b in nc..nh {
        if face_or_loop[b] != NONE {
            continue;
        }
        let id = (face_count + loop_halfedge.len()) as u32;
        loop_halfedge.push(HalfedgeId(b as u32));
        let mut h = b;
        loop {
            face_or_loop[h] = id;
            h = next[h] as usize;
            if h == b {
                break;
            }
        }
    }
    (face_or_loop, loop_halfedge)
}

/// Creates the halfedge arrays from oriented, manifold-edged faces, checks the vertex
/// fans and links boundary loops.
fn assemble(
    soup: &PolygonSoup,
    oriented: OrientedFaces,
    representative: Option<&[u32]>,
    mut report: BuildReport,
) -> Result<(Mesh, BuildReport), MeshError> {
    let OrientedFaces {
        faces,
        groups,
        orientation,
        corner_face,
        next_corner,
    } = oriented;
    let vertices = compact_vertices(soup, &faces, representative, &mut report);
    let edge_count = groups.edge_count;
    let mut halfedges = HalfedgeArrays::interior(&faces, next_corner, groups, &vertices.new_id);
    let out_boundary = halfedges.add_boundary(vertices.to_input.len(), &vertices.to_input)?;
    let vertex_halfedge = halfedges.vertex_halfedges(&out_boundary);
    halfedges.check_fans(&vertex_halfedge, &vertices.to_input)?;
    let (face_or_loop, loop_halfedge) = boundary_loops(corner_face, &halfedges.next, faces.len());

    let vertex_map = VertexMap::new(
        vertices.to_input,
        vertices.from_input,
        vertices.unreferenced,
    );
    let data = MeshData {
        positions: vertices.positions,
        next: into_ids(halfedges.next, HalfedgeId),
        prev: into_ids(halfedges.prev, HalfedgeId),
        twin: into_ids(halfedges.twin, HalfedgeId),
        origin: into_ids(halfedges.origin, VertexId),
        edge: into_ids(halfedges.edge, EdgeId),
        face_or_loop,
        vertex_halfedge: into_ids(vertex_halfedge, HalfedgeId),
        face_offsets: faces.offsets,
        edge_count,
        loop_halfedge,
        face_component: into_ids(orientation.face_component, ComponentId),
        component_count: orientation.component_count,
        vertex_map,
        face_to_input: faces.input,
    };
    Ok((Mesh::from_data(data), report))
}

fn into_ids<T>(v: Vec<u32>, f: impl Fn(u32) -> T) -> Vec<T> {
    v.into_iter().map(f).collect()
}

/// The error for mesh vertex `v`, with the number of fans around it: the connected
/// groups of its interior outgoing halfedges, where `h` and `twin(prev(h))` are joined
/// when both are interior (they bound the same face pair across an edge at `v`).
fn non_manifold_vertex(
    interior: usize,
    origin: &[u32],
    twin: &[u32],
    prev: &[u32],
    to_input: &[u32],
    v: u32,
) -> MeshError {
    let outgoing: Vec<usize> = (0..interior).filter(|&h| origin[h] == v).collect();
    let mut group: Vec<usize> = (0..outgoing.len()).collect();
    fn find(group: &mut [usize], mut i: usize) -> usize {
        while group[i] != i {
            group[i] = group[group[i]];
            i = group[i];
        }
        i
    }
    for (i, &h) in outgoing.iter().enumerate() {
        let t = twin[prev[h] as usize] as usize;
        if let Some(j) = outgoing.iter().position(|&o| o == t) {
            let (a, b) = (find(&mut group, i), find(&mut group, j));
            group[a] = b;
        }
    }
    let fans = (0..outgoing.len())
        .filter(|&i| find(&mut group, i) == i)
        .count();
    MeshError::NonManifoldVertex {
        vertex: to_input[v as usize] as usize,
        fans: fans.max(2),
    }
}
