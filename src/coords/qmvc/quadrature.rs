//! The numerical term of QMVC: `∫ ψ(u, v) (P − x)·n / |P − x|⁴ du dv` over the
//! parameter square, by tensor Gauss–Legendre on the cells of a quadtree that
//! is refined where a cell is large beside its distance to `x`.
//!
//! Why adaptive: the integrand peaks, with width about the distance `h` from
//! `x` to the patch, where `x` is nearest it. A fixed grid is accurate far from
//! the patch and wrong near it: the authors' 9 × 9 grid is 6e-3 off in the
//! weights well inside a twisted box and 6e-2 near its patches; one 6 × 6 Gauss
//! grid 2e-2 and 0.8 (see the convergence tests). A cell whose bounding radius
//! is at most [`Rule::eta`] times its centre's distance from `x` sees a smooth
//! integrand, so cells shrink geometrically towards the nearest point and a
//! point at `h` costs `O(log(1/h))` cells; far cells get fewer nodes. The
//! weights are smooth in `x` but where the tree changes, where they move by
//! the quadrature error.

use crate::geometry::quads::bilinear_basis;
use glam::DVec3;

/// The quadtree's cells are refined while a cell's bounding radius exceeds `eta`
/// times its centre's distance from `x`; a leaf gets the fewest Gauss–Legendre
/// nodes per side (2 to 8, or exactly `order` when it is set) whose error
/// model, `ρ^(−2n)` for the kernel's nearest complex singularity at Bernstein
/// ellipse `ρ`, is below `tau`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rule {
    pub eta: f64,
    pub tau: f64,
    pub order: Option<usize>,
}

/// The rule QMVC use: the weights within 1e-8 of converged inside a twisted
/// box, well inside and at 1e-1 to 1e-4 from its bent patches, 3e-7 inside a
/// comb of quads and 7e-8 on the Ogre's points, with 30 evaluations per quad
/// there (see the convergence tests; the authors' grid takes 81).
pub const RULE: Rule = Rule {
    eta: 0.6,
    tau: 1e-6,
    order: None,
};

/// The integral, or where `x` lies on the patch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integral {
    /// `x` is on the patch, where these are its corners' bilinear weights.
    OnPatch([f64; 4]),
    Value([f64; 4]),
}

/// Deeper cells than this are integrated as they are: their size is below
/// 1e-18 of the patch's, far under any tolerance.
const MAX_DEPTH: u32 = 60;

/// The integral over the patch `q` at `x` by `rule`; `OnPatch` where `x` is
/// within `tolerance` of it.
pub fn integrate(x: DVec3, q: &[DVec3; 4], tolerance: f64, rule: &Rule) -> Integral {
    integrate_counting(x, q, tolerance, rule).0
}

/// [`integrate`] and the number of integrand evaluations it took.
pub fn integrate_counting(
    x: DVec3,
    q: &[DVec3; 4],
    tolerance: f64,
    rule: &Rule,
) -> (Integral, usize) {
    let mut tree = Quadtree {
        patch: Patch::new(x, q),
        tolerance,
        rule,
        sum: [0.0; 4],
        samples: 0,
    };
    match tree.cell(0.0, 0.0, 1.0, 0) {
        Some(basis) => (Integral::OnPatch(basis), tree.samples),
        None => (Integral::Value(tree.sum), tree.samples),
    }
}

struct Quadtree<'a> {
    patch: Patch,
    tolerance: f64,
    rule: &'a Rule,
    sum: [f64; 4],
    samples: usize,
}

impl Quadtree<'_> {
    /// Integrate the cell `[u, u + size] × [v, v + size]` into `sum`, or return
    /// the bilinear weights where `x` is on it.
    fn cell(&mut self, u: f64, v: f64, size: f64, depth: u32) -> Option<[f64; 4]> {
        let half = 0.5 * size;
        let (cu, cv) = (u + half, v + half);
        let centre = self.patch.offset(cu, cv);
        let distance = centre.length();
        let radius = [(u, v), (u + size, v), (u + size, v + size), (u, v + size)]
            .into_iter()
            .map(|(u, v)| self.patch.offset(u, v).distance_squared(centre))
            .fold(0.0, f64::max)
            .sqrt();
        if radius <= self.tolerance && distance <= radius + self.tolerance {
            return Some(bilinear_basis(cu, cv));
        }
        if radius > self.rule.eta * distance && depth < MAX_DEPTH {
            for (du, dv) in [(0.0, 0.0), (half, 0.0), (half, half), (0.0, half)] {
                if let Some(basis) = self.cell(u + du, v + dv, half, depth + 1) {
                    return Some(basis);
                }
            }
            return None;
        }
        let order = self
            .rule
            .order
            .unwrap_or_else(|| order_for(distance / radius, self.rule.tau));
        self.leaf(cu, cv, half, order);
        None
    }

    /// Tensor Gauss–Legendre of `order` on the cell of centre `(cu, cv)`.
    fn leaf(&mut self, cu: f64, cv: f64, half: f64, order: usize) {
        let (nodes, weights) = gauss_legendre(order);
        let patch = &self.patch;
        let mut sum = [0.0; 4];
        for (&s, &ws) in nodes.iter().zip(weights) {
            let u = cu + half * s;
            // Along the row: P − x = a + v·f and the normal n + v·nv.
            let (a, f) = (patch.a + u * patch.e, patch.f + u * patch.k);
            let n = patch.n + u * patch.nu;
            let (mut low, mut high) = (0.0, 0.0);
            for (&t, &wt) in nodes.iter().zip(weights) {
                let v = cv + half * t;
                let offset = a + v * f;
                let r2 = offset.length_squared();
                let g = wt * offset.dot(n + v * patch.nv) / (r2 * r2);
                low += g * (1.0 - v);
                high += g * v;
            }
            sum[0] += ws * (1.0 - u) * low;
            sum[1] += ws * u * low;
            sum[2] += ws * u * high;
            sum[3] += ws * (1.0 - u) * high;
        }
        let area = half * half;
        for (total, value) in self.sum.iter_mut().zip(sum) {
            *total += area * value;
        }
        self.samples += order * order;
    }
}

/// The fewest nodes per side, from 2 to 8, with `ρ^(−2n) ≤ tau`, where the
/// kernel's singularity lies `t` half-sizes off the cell: `ρ = t + √(1 + t²)`.
pub(crate) fn order_for(t: f64, tau: f64) -> usize {
    let rho_squared = (t + (1.0 + t * t).sqrt()).powi(2);
    let mut power = rho_squared * rho_squared;
    let mut order = 2;
    while power * tau < 1.0 && order < 8 {
        power *= rho_squared;
        order += 1;
    }
    order
}

/// The patch relative to `x`: `P − x = a + u·e + v·f + uv·k`, and its normal
/// `∂P/∂u × ∂P/∂v = n + u·nu + v·nv`, linear since `k × k = 0`.
struct Patch {
    a: DVec3,
    e: DVec3,
    f: DVec3,
    k: DVec3,
    n: DVec3,
    nu: DVec3,
    nv: DVec3,
}

impl Patch {
    fn new(x: DVec3, q: &[DVec3; 4]) -> Self {
        let (e, f, k) = (q[1] - q[0], q[3] - q[0], q[0] - q[1] + q[2] - q[3]);
        Patch {
            a: q[0] - x,
            e,
            f,
            k,
            n: e.cross(f),
            nu: e.cross(k),
            nv: k.cross(f),
        }
    }

    #[inline]
    fn offset(&self, u: f64, v: f64) -> DVec3 {
        self.a + u * self.e + v * (self.f + u * self.k)
    }
}

/// Gauss–Legendre nodes and weights on [−1, 1] (Abramowitz and Stegun, Table
/// 25.4), for orders 2 to 8; other orders get 4.
pub fn gauss_legendre(order: usize) -> (&'static [f64], &'static [f64]) {
    const X2: f64 = 0.577_350_269_189_625_8;
    const X3: f64 = 0.774_596_669_241_483_4;
    const X4: [f64; 2] = [0.339_981_043_584_856_3, 0.861_136_311_594_052_6];
    const W4: [f64; 2] = [0.652_145_154_862_546_1, 0.347_854_845_137_453_9];
    const X5: [f64; 2] = [0.538_469_310_105_683_1, 0.906_179_845_938_664];
    const W5: [f64; 3] = [
        0.568_888_888_888_888_9,
        0.478_628_670_499_366_5,
        0.236_926_885_056_189_1,
    ];
    const X6: [f64; 3] = [
        0.238_619_186_083_196_9,
        0.661_209_386_466_264_5,
        0.932_469_514_203_152,
    ];
    const W6: [f64; 3] = [
        0.467_913_934_572_691,
        0.360_761_573_048_138_6,
        0.171_324_492_379_170_3,
    ];
    const X7: [f64; 3] = [
        0.405_845_151_377_397_2,
        0.741_531_185_599_394_5,
        0.949_107_912_342_758_5,
    ];
    const W7: [f64; 4] = [
        0.417_959_183_673_469_4,
        0.381_830_050_505_118_9,
        0.279_705_391_489_276_7,
        0.129_484_966_168_869_7,
    ];
    const X8: [f64; 4] = [
        0.183_434_642_495_649_8,
        0.525_532_409_916_329,
        0.796_666_477_413_626_7,
        0.960_289_856_497_536_3,
    ];
    const W8: [f64; 4] = [
        0.362_683_783_378_362,
        0.313_706_645_877_887_3,
        0.222_381_034_453_374_5,
        0.101_228_536_290_376_3,
    ];
    match order {
        7 => (
            &[-X7[2], -X7[1], -X7[0], 0.0, X7[0], X7[1], X7[2]],
            &[W7[3], W7[2], W7[1], W7[0], W7[1], W7[2], W7[3]],
        ),
        8 => (
            &[-X8[3], -X8[2], -X8[1], -X8[0], X8[0], X8[1], X8[2], X8[3]],
            &[W8[3], W8[2], W8[1], W8[0], W8[0], W8[1], W8[2], W8[3]],
        ),
        2 => (&[-X2, X2], &[1.0, 1.0]),
        3 => (&[-X3, 0.0, X3], &[5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0]),
        5 => (
            &[-X5[1], -X5[0], 0.0, X5[0], X5[1]],
            &[W5[2], W5[1], W5[0], W5[1], W5[2]],
        ),
        6 => (
            &[-X6[2], -X6[1], -X6[0], X6[0], X6[1], X6[2]],
            &[W6[2], W6[1], W6[0], W6[0], W6[1], W6[2]],
        ),
        _ => (
            &[-X4[1], -X4[0], X4[0], X4[1]],
            &[W4[1], W4[0], W4[0], W4[1]],
        ),
    }
}
