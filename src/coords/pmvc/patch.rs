//! Quads as bilinear patches `P(u, v) = q0 + u·(q1 − q0) + v·(q3 − q0) + uv·(q0 − q1 + q2 − q3)`
//! in the per-face depth test, and the weights of their hits.
//!
//! A ray along d (from x, corners taken relative to x) meets the patch at parameter
//! u exactly when d lies in the plane through x and the segment `S0(u) = P(u, 0)`,
//! `S1(u) = P(u, 1)`: `g(u) = d·(S0(u) × S1(u)) = 0`, a quadratic whose Bernstein
//! coefficients `d·(q0×q3)`, `d·(q0×q2 + q1×q3)`, `d·(q1×q2)` are linear in the texel
//! coordinates, like a triangle's edge functions. Where they all have one sign no
//! root lies in [0, 1] (likewise for v), which rejects most texels outside the patch
//! cheaply: those groups of texels are listed first, then solved. Each root of g
//! (in the stable form) gives v along its segment by least squares and t; a ray
//! that meets a bent patch twice keeps the nearer hit. The solve is written once
//! over [`Lanes`], for the portable and the AVX2 code alike, and runs two texel
//! groups side by side ([`Pair`]) so that their chains through a square root and a
//! division overlap.
//!
//! A hit weighs `Ω/t` spread by the bilinear basis; each texel stores u and
//! `(1 − v)/t`, `v/t`, so the resolve needs no division.

use super::super::cubemap::{TexelTable, TEXEL_LANES};
use super::frustum::FaceFrame;
use super::lanes::{four, six, splat_bits, Lanes, Pair};
use glam::DVec3;
use std::ops::Range;

/// One patch at one cage vertex x.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct PatchSetup {
    /// Cage vertices q0..q3.
    pub(crate) vertices: [u32; 4],
    /// Corners relative to x, times `scale`.
    pub(crate) corners: [DVec3; 4],
    /// A power of two near the inverse size of `corners` (exact to apply): the solve
    /// forms products of up to eleven corner coordinates, kept in range this way.
    pub(crate) scale: f64,
}

impl PatchSetup {
    pub(crate) fn new(vertices: [u32; 4], relative: [DVec3; 4]) -> Self {
        let size = relative
            .iter()
            .map(|p| p.abs().max_element())
            .fold(0.0, f64::max);
        let exponent = ((size.to_bits() >> 52) & 0x7ff).clamp(1, 2045);
        let scale = f64::from_bits((2046 - exponent) << 52);
        Self {
            vertices,
            corners: relative.map(|p| p * scale),
            scale,
        }
    }

    /// `det[q_k, q_k+1, q_k−1]` per corner k: the side of x of the patch's tangent
    /// plane there (negative outside). The patch's `(P − x)·n(u, v)` is bilinear in
    /// (u, v) (n is linear in them), so these four bound its sign everywhere.
    pub(crate) fn corner_sides(&self) -> [f64; 4] {
        let q = &self.corners;
        std::array::from_fn(|k| q[k].dot(q[(k + 1) % 4].cross(q[(k + 3) % 4])))
    }

    /// The patch's functions in the coordinates of one cube face.
    pub(crate) fn on_face(&self, frame: &FaceFrame, code_mask: usize, code: u64) -> FacePatch {
        let [q0, q1, q2, q3] = self.corners.map(|p| frame.local(p));
        FacePatch {
            along_u: [q0.cross(q3), q0.cross(q2) + q1.cross(q3), q1.cross(q2)],
            along_v: [q0.cross(q1), q0.cross(q2) + q3.cross(q1), q3.cross(q2)],
            origin: q0,
            edge_u: q1 - q0,
            edge_v: q3 - q0,
            twist: (q0 - q1) + (q2 - q3),
            scale: self.scale,
            code_mask,
            code,
        }
    }
}

/// A patch's solve on one cube face, for a texel ray `d = (s, r, 1)`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct FacePatch {
    /// Bernstein coefficients of g(u) (u = 0, middle, u = 1) as `x·s + y·r + z`.
    along_u: [DVec3; 3],
    /// The same for v: `d·(q0×q1)`, `d·(q0×q2 + q3×q1)`, `d·(q3×q2)`.
    along_v: [DVec3; 3],
    origin: DVec3,
    edge_u: DVec3,
    edge_v: DVec3,
    twist: DVec3,
    scale: f64,
    code_mask: usize,
    code: u64,
}

/// Per texel of a face, for the patch that holds it in the depth buffer: u and the
/// weights `(1 − v)/t`, `v/t` (true units) of the edges v = 0 and v = 1; and the
/// lists the raster and the resolve share.
#[derive(Debug, Default)]
pub(super) struct PatchHits {
    u: Vec<f64>,
    below: Vec<f64>,
    above: Vec<f64>,
    /// The texel groups the face's patches may hit, as `row << 16 | column` of their
    /// first texel, patch after patch.
    candidates: Vec<u32>,
    /// Per row, the values of the patch being drawn (see [`FacePatch::row_values`]).
    rows: Vec<[f64; 10]>,
    /// `Ω/|(s, r, 1)|` per texel in the padded layout (zero in the padding), for
    /// the resolution `weights_resolution`.
    weights: Vec<f64>,
    weights_resolution: u32,
}

impl PatchHits {
    /// Ready for `table`'s faces.
    pub(super) fn prepare(&mut self, table: &TexelTable) {
        let texels = table.texel_directions.len();
        for values in [&mut self.u, &mut self.below, &mut self.above] {
            values.resize(texels, 0.0);
        }
        self.rows.resize(table.resolution as usize, [0.0; 10]);
        if self.weights_resolution != table.resolution || self.weights.len() != texels {
            self.weights.clear();
            self.weights
                .extend(table.texel_directions.iter().map(|direction| direction[2]));
            self.weights_resolution = table.resolution;
        }
    }

    /// Before the patches of a new face.
    pub(super) fn start_face(&mut self) {
        self.candidates.clear();
    }

    /// Where the candidates of the next patch will start.
    pub(super) fn candidate_count(&self) -> usize {
        self.candidates.len()
    }

    /// The corners' weights, `Σ Ω/t · ψₖ(u, v)`, of the patch coded `code` over the
    /// texels it holds among its candidate groups `candidates`.
    #[inline(always)]
    pub(super) fn resolve<V: Lanes>(
        &self,
        candidates: Range<usize>,
        stride: usize,
        nearest: &[f64],
        code_mask: usize,
        code: u64,
    ) -> [f64; 4] {
        let (mask, code) = (splat_bits::<V>(code_mask as u64), splat_bits::<V>(code));
        let one = V::splat(1.0);
        let mut sums = [V::splat(0.0); 4];
        for &group in &self.candidates[candidates] {
            let texel = (group >> 16) as usize * stride + (group & 0xffff) as usize;
            let held = V::load(&nearest[texel..]).and(mask).equal(code);
            let u = V::load(&self.u[texel..]);
            let weight = V::load(&self.weights[texel..]);
            let below = V::load(&self.below[texel..]).mul(weight);
            let above = V::load(&self.above[texel..]).mul(weight);
            let rest = one.sub(u);
            let shares = [rest.mul(below), u.mul(below), u.mul(above), rest.mul(above)];
            for (sum, share) in sums.iter_mut().zip(shares) {
                *sum = sum.add(held.and(share));
            }
        }
        four(|k| sums[k].sum())
    }
}

/// A patch's constants on one face, in lanes: what the kernel reads per texel.
#[derive(Clone, Copy)]
struct Constants<V> {
    /// Slopes in s of the Bernstein coefficient functions (g's, then h's).
    slopes: [V; 6],
    /// `k.x` and `−k.z` for k = q0, q1 − q0, q3 − q0 and the twist: `X_k = k.x − s·k.z`.
    x: [V; 4],
    minus_z: [V; 4],
    /// `k.z`.
    z: [V; 4],
    scale: V,
    key_bits: V,
    code: V,
}

impl<V: Lanes> Constants<V> {
    /// The same constants in both halves of a [`Pair`].
    #[inline(always)]
    fn pair(&self) -> Constants<Pair<V>> {
        let both = |v: &V| Pair(*v, *v);
        Constants {
            slopes: six(|k| both(&self.slopes[k])),
            x: four(|k| both(&self.x[k])),
            minus_z: four(|k| both(&self.minus_z[k])),
            z: four(|k| both(&self.z[k])),
            scale: both(&self.scale),
            key_bits: both(&self.key_bits),
            code: both(&self.code),
        }
    }
}

/// Per row: the offsets of the six coefficient functions and `Y_k = k.y − r·k.z`.
struct Row<V> {
    offsets: [V; 6],
    y: [V; 4],
}

impl<V: Lanes> Row<V> {
    #[inline(always)]
    fn new(values: &[f64; 10]) -> Self {
        Self {
            offsets: six(|k| V::splat(values[k])),
            y: four(|k| V::splat(values[6 + k])),
        }
    }

    /// Two rows' values, one per half of a [`Pair`].
    #[inline(always)]
    fn pair(first: &[f64; 10], second: &[f64; 10]) -> Row<Pair<V>> {
        let [first, second] = [Self::new(first), Self::new(second)];
        Row {
            offsets: six(|k| Pair(first.offsets[k], second.offsets[k])),
            y: four(|k| Pair(first.y[k], second.y[k])),
        }
    }
}

/// The depth test of a group at `texel` on: keeps the larger key in `nearest` and,
/// where the patch's is larger, its u and weights in `hits`.
#[inline(always)]
fn keep<V: Lanes>(
    texel: usize,
    key: V,
    [u, below, above]: [V; 3],
    nearest: &mut [f64],
    [us, belows, aboves]: [&mut [f64]; 3],
) {
    let kept = V::load(&nearest[texel..]);
    let wins = key.greater(kept);
    key.max(kept).store(&mut nearest[texel..]);
    for (values, new) in [(us, u), (belows, below), (aboves, above)] {
        let values = &mut values[texel..];
        wins.select(new, V::load(values)).store(values);
    }
}

/// A texel group's hit on the patch: its depth-test key (0 where there is none),
/// u, and the weights `(1 − v)/t`, `v/t` in true units.
pub(super) struct Hit<V> {
    pub(super) key: V,
    pub(super) u: V,
    pub(super) below: V,
    pub(super) above: V,
}

const SIGN: u64 = 1 << 63;

/// How far outside [0, 1] a patch's u and v may round and still count as on it:
/// far above the solve's rounding, far below a texel (the hit is clamped onto the
/// patch, so its weight moves by about this much).
const RANGE_SLACK: f64 = 1e-10;

impl FacePatch {
    #[inline(always)]
    fn constants<V: Lanes>(&self) -> Constants<V> {
        let [l0, m0, r0] = self.along_u;
        let [l1, m1, r1] = self.along_v;
        let corners = [self.origin, self.edge_u, self.edge_v, self.twist];
        Constants {
            slopes: six(|k| V::splat([l0.x, m0.x, r0.x, l1.x, m1.x, r1.x][k])),
            x: four(|k| V::splat(corners[k].x)),
            minus_z: four(|k| V::splat(-corners[k].z)),
            z: four(|k| V::splat(corners[k].z)),
            scale: V::splat(self.scale),
            key_bits: splat_bits(!(self.code_mask as u64)),
            code: splat_bits(self.code),
        }
    }

    /// [`Row`]'s values at `r`, before they are put in lanes.
    #[inline(always)]
    fn row_values(&self, r: f64) -> [f64; 10] {
        let [l0, m0, r0] = self.along_u;
        let [l1, m1, r1] = self.along_v;
        let [a, b, c, e] = [self.origin, self.edge_u, self.edge_v, self.twist];
        let offset = |f: DVec3| r.mul_add(f.y, f.z);
        let y = |k: DVec3| r.mul_add(-k.z, k.y);
        [
            offset(l0),
            offset(m0),
            offset(r0),
            offset(l1),
            offset(m1),
            offset(r1),
            y(a),
            y(b),
            y(c),
            y(e),
        ]
    }

    /// The six Bernstein coefficient functions at the rays `(s, r, 1)` of a group.
    #[inline(always)]
    fn coefficients<V: Lanes>(c: &Constants<V>, row: &Row<V>, s: V) -> [V; 6] {
        six(|k| s.mul_add(c.slopes[k], row.offsets[k]))
    }

    /// Whether a lane of the group may hit the patch: a polynomial whose Bernstein
    /// coefficients share a sign has no root in [0, 1], so a candidate has a
    /// negative and a non-negative coefficient among g's and among h's.
    #[inline(always)]
    fn candidate<V: Lanes>(f: &[V; 6]) -> bool {
        let all_negative = f[0].and(f[1]).and(f[2]).or(f[3].and(f[4]).and(f[5]));
        let any_negative = f[0].or(f[1]).or(f[2]).and(f[3].or(f[4]).or(f[5]));
        all_negative.and_not(any_negative).signs() != 0
    }

    /// The nearer hit of the rays `(s, r, 1)` of a texel group.
    #[inline(always)]
    fn group<V: Lanes>(&self, c: &Constants<V>, row: &Row<V>, s: V) -> Hit<V> {
        let [gl, gm, gr, ..] = Self::coefficients(c, row, s);
        let zero = V::splat(0.0);
        let sign = splat_bits::<V>(SIGN);
        // g(u) = γ + β·u + α·u², solved as u = γ/q and u = q/α.
        let alpha = gl.add(gr).sub(gm);
        let beta = gl.mul_add(V::splat(-2.0), gm);
        let discriminant = beta.mul_add(beta, alpha.mul(V::splat(-4.0)).mul(gl));
        let root = discriminant.max(zero).sqrt();
        let q = beta.and(sign).or(root).add(beta).mul(V::splat(-0.5));
        let x = four(|k| s.mul_add(c.minus_z[k], c.x[k]));
        let hit = self.hit(c, row, &x, gl, q, discriminant);
        // q/α lies in [0, 1] only on a patch bent enough to be met twice.
        let along = q.mul(alpha);
        let room = alpha.mul(alpha).sub(along);
        if (!along.or(room).or(discriminant).signs() & V::ALL) == 0 {
            return hit;
        }
        let other = self.hit(c, row, &x, q, alpha, discriminant);
        let nearer = other.key.greater(hit.key);
        Hit {
            key: nearer.select(other.key, hit.key),
            u: nearer.select(other.u, hit.u),
            below: nearer.select(other.below, hit.below),
            above: nearer.select(other.above, hit.above),
        }
    }

    /// The hit at the root `u = n/d` of g. Everything is kept multiplied by powers
    /// of d so that one division gives u, `1/t` and v: the segment `S0 + v·D` of the
    /// root, projected along the ray to `A + v·B = 0` (A, B from `X_k`, `Y_k`), gives
    /// `v = −A·B/B·B` by least squares, and `t = S0.z + v·D.z`.
    #[inline(always)]
    fn hit<V: Lanes>(
        &self,
        c: &Constants<V>,
        row: &Row<V>,
        x: &[V; 4],
        n: V,
        d: V,
        discriminant: V,
    ) -> Hit<V> {
        let (zero, one) = (V::splat(0.0), V::splat(1.0));
        let [ya, yb, yc, ye] = row.y;
        let ax = n.mul_add(x[1], d.mul(x[0]));
        let ay = n.mul_add(yb, d.mul(ya));
        let bx = n.mul_add(x[3], d.mul(x[2]));
        let by = n.mul_add(ye, d.mul(yc));
        let numerator = ax.mul_add(bx, ay.mul(by)).xor(splat_bits(SIGN));
        let denominator = bx.mul_add(bx, by.mul(by));
        let start = n.mul_add(c.z[1], d.mul(c.z[0]));
        let along = n.mul_add(c.z[3], d.mul(c.z[2]));
        let depth = start.mul_add(denominator, numerator.mul(along));
        // d·depth = d⁴·t·(B·B): positive exactly when t > 0.
        let signed = d.mul(depth);
        let (nd, dd) = (n.mul(d), d.mul(d));
        // u = n/d and v in [−ε, 1 + ε] (ε = RANGE_SLACK) and a real root: no sign bit
        // set. A ray along the edge two patches share may round to just outside
        // both; with the slack both take it, and the depth test picks one.
        let slack = V::splat(RANGE_SLACK);
        let outside = slack
            .mul_add(dd, nd)
            .or(slack.mul_add(dd, dd.sub(nd)))
            .or(slack.mul_add(denominator, numerator))
            .or(slack.mul_add(denominator, denominator.sub(numerator)))
            .or(discriminant);
        let inverse = one.div(signed);
        let factor = dd.mul(inverse.mul(c.scale));
        let key = factor.mul(denominator).and(c.key_bits).or(c.code);
        // v·(B·B), clamped into [0, B·B] as u into [0, 1].
        let numerator = numerator.max(zero).min(denominator);
        Hit {
            key: outside.select(zero, key).and(signed.greater(zero)),
            u: n.mul(depth).mul(inverse).max(zero).min(one),
            below: factor.mul(denominator.sub(numerator)),
            above: factor.mul(numerator),
        }
    }

    /// Keeps in `nearest` the larger of its key and the patch's key at each texel of
    /// `rows × columns` (whole steps of [`TEXEL_LANES`]), and in `hits` the patch's
    /// u and weights where it wins. The padding's NaN centres never hit.
    #[inline(always)]
    pub(super) fn raster<V: Lanes>(
        &self,
        rows: Range<usize>,
        columns: Range<usize>,
        table: &TexelTable,
        nearest: &mut [f64],
        hits: &mut PatchHits,
    ) {
        let c = self.constants::<V>();
        let centres = &table.padded_centres[columns.clone()];
        let groups = columns.len() / TEXEL_LANES;
        // First the candidate groups of every row, listed without a branch per group
        // to mispredict; then those alone, in one loop whose groups overlap in flight
        // (a group's solve is a long chain through a square root and a division).
        let start = hits.candidates.len();
        hits.candidates.resize(start + rows.len() * groups, 0);
        let mut count = start;
        for j in rows.clone() {
            let values = self.row_values(table.centres[j]);
            hits.rows[j] = values;
            let row = Row::new(&values);
            for (step, s) in centres.chunks_exact(TEXEL_LANES).enumerate() {
                let f = Self::coefficients(&c, &row, V::load(s));
                let column = columns.start + step * TEXEL_LANES;
                hits.candidates[count] = (j << 16 | column) as u32;
                count += usize::from(Self::candidate(&f));
            }
        }
        hits.candidates.truncate(count);
        // Two groups at a time, side by side (see `Pair`).
        let place = |group: u32| {
            let (j, column) = ((group >> 16) as usize, (group & 0xffff) as usize);
            (j, column - columns.start, j * table.stride + column)
        };
        let PatchHits {
            u,
            below,
            above,
            candidates,
            rows: row_values,
            ..
        } = hits;
        let mut pairs = candidates[start..].chunks_exact(2);
        for pair in &mut pairs {
            let [(i0, k0, texel0), (i1, k1, texel1)] = [place(pair[0]), place(pair[1])];
            let row = Row::pair(&row_values[i0], &row_values[i1]);
            let s = Pair(V::load(&centres[k0..]), V::load(&centres[k1..]));
            let hit = self.group(&c.pair(), &row, s);
            let halves = [
                (texel0, hit.key.0, [hit.u.0, hit.below.0, hit.above.0]),
                (texel1, hit.key.1, [hit.u.1, hit.below.1, hit.above.1]),
            ];
            for (texel, key, values) in halves {
                keep(texel, key, values, nearest, [u, below, above]);
            }
        }
        if let [group] = *pairs.remainder() {
            let (i, k, texel) = place(group);
            let hit = self.group(&c, &Row::new(&row_values[i]), V::load(&centres[k..]));
            keep(
                texel,
                hit.key,
                [hit.u, hit.below, hit.above],
                nearest,
                [u, below, above],
            );
        }
    }

    /// A missed texel's ray `(s, r, 1)` cast again with `slack` in u and v: `1/t`, u
    /// and the weights `(1 − v)/t`, `v/t`, or `None`.
    pub(crate) fn hit_with_slack(&self, s: f64, r: f64, slack: f64) -> Option<[f64; 4]> {
        let eval = |edge: DVec3| s.mul_add(edge.x, r.mul_add(edge.y, edge.z));
        let [gl, gm, gr] = self.along_u.map(eval);
        let alpha = (gl + gr) - gm;
        let beta = (-2.0f64).mul_add(gl, gm);
        let discriminant = beta.mul_add(beta, -(4.0 * alpha * gl));
        if discriminant.is_nan() || discriminant < 0.0 {
            return None;
        }
        let q = -0.5 * (beta + discriminant.sqrt().copysign(beta));
        let mut best: Option<[f64; 4]> = None;
        for u in [gl / q, q / alpha] {
            if !(-slack..=1.0 + slack).contains(&u) {
                continue;
            }
            let start = self.origin + u * self.edge_u;
            let along = self.edge_v + u * self.twist;
            let project = |p: DVec3| (p.x - s * p.z, p.y - r * p.z);
            let (a, b) = (project(start), project(along));
            let denominator = b.0 * b.0 + b.1 * b.1;
            let v = -(a.0 * b.0 + a.1 * b.1) / denominator;
            if !(-slack..=1.0 + slack).contains(&v) {
                continue;
            }
            let (u, v) = (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
            let t = (start + v * along).z;
            let inverse_t = self.scale / t;
            if t > 0.0 && best.is_none_or(|[nearest, ..]| inverse_t > nearest) {
                best = Some([inverse_t, u, (1.0 - v) * inverse_t, v * inverse_t]);
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::super::lanes::Portable;
    use super::*;
    use crate::geometry::quads::bilinear_point;

    /// The saddle `(u, v, uv)` seen along `(1, −1, 0)` at height 0.1: that line
    /// meets it at u = (1 ± √0.6)/2, v = 1 − u. Placed so that the line is the ray
    /// `(0, 0, 1)` of the +Z face from x = 0, the patch must give the nearer hit.
    #[test]
    fn a_ray_that_meets_a_bent_patch_twice_takes_the_nearer_hit() {
        let axes = [
            DVec3::new(1.0, 1.0, 0.0) / 2f64.sqrt(),
            DVec3::Z,
            DVec3::new(1.0, -1.0, 0.0) / 2f64.sqrt(),
        ];
        let centre = DVec3::new(0.5, 0.5, 0.1);
        let place = |p: DVec3| {
            let p = p - centre;
            DVec3::new(p.dot(axes[0]), p.dot(axes[1]), p.dot(axes[2]) + 2.0)
        };
        let saddle = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .map(|(u, v)| place(DVec3::new(u, v, u * v)));
        // Either way round in u, so that each root of g is the nearer once.
        let near = (1.0 - 0.6f64.sqrt()) / 2.0;
        for (corners, (near_u, near_v), (far_u, far_v)) in [
            (saddle, (near, 1.0 - near), (1.0 - near, near)),
            (
                [saddle[1], saddle[0], saddle[3], saddle[2]],
                (1.0 - near, 1.0 - near),
                (near, near),
            ),
        ] {
            let setup = PatchSetup::new([0, 1, 2, 3], corners);
            let patch = setup.on_face(&super::super::frustum::FACE_FRAMES[4], 1, 1);
            let point = bilinear_point(&corners, near_u, near_v);
            assert!(point.x.abs() < 1e-12 && point.y.abs() < 1e-12);
            let far = bilinear_point(&corners, far_u, far_v);
            assert!(far.x.abs() < 1e-12 && far.y.abs() < 1e-12);
            assert!(far.z > point.z + 1.0, "the other hit is farther");
            let expected = [
                1.0 / point.z,
                near_u,
                (1.0 - near_v) / point.z,
                near_v / point.z,
            ];
            let c = patch.constants::<Portable>();
            let row = Row::new(&patch.row_values(0.0));
            let f = FacePatch::coefficients(&c, &row, Portable::splat(0.0));
            assert!(FacePatch::candidate(&f));
            let hit = patch.group(&c, &row, Portable::splat(0.0));
            let inverse_t = f64::from_bits(hit.key.lane(0).to_bits() & !1);
            let lane = [
                inverse_t,
                hit.u.lane(0),
                hit.below.lane(0),
                hit.above.lane(0),
            ];
            let slack = patch.hit_with_slack(0.0, 0.0, 0.0).expect("a hit");
            for (got, want) in lane.iter().zip(expected).chain(slack.iter().zip(expected)) {
                assert!(
                    (got - want).abs() < 1e-12,
                    "{lane:?} / {slack:?} vs {expected:?}"
                );
            }
        }
    }
}
