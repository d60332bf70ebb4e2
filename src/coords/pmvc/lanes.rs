//! Four f64 lanes for the patch kernel, portable or in one AVX2 register. Every
//! operation rounds as IEEE 754 requires (fused multiply-adds included), so the two
//! give bit-identical results. Masks are lanes whose sign bit is what counts.

/// The kernel's lane type. Methods are `#[inline(always)]`: instantiated inside a
/// function compiled for AVX2, they compile to single instructions.
pub(super) trait Lanes: Copy {
    /// [`Lanes::signs`] with every lane's bit set.
    const ALL: u32;
    fn splat(value: f64) -> Self;
    /// The first four values of `values`.
    fn load(values: &[f64]) -> Self;
    /// Into the first four values of `values`.
    fn store(self, values: &mut [f64]);
    fn add(self, other: Self) -> Self;
    fn sub(self, other: Self) -> Self;
    fn mul(self, other: Self) -> Self;
    fn div(self, other: Self) -> Self;
    /// `self·a + b`, rounded once.
    fn mul_add(self, a: Self, b: Self) -> Self;
    fn sqrt(self) -> Self;
    fn and(self, other: Self) -> Self;
    fn or(self, other: Self) -> Self;
    /// `!self & other`.
    fn and_not(self, other: Self) -> Self;
    fn xor(self, other: Self) -> Self;
    /// All ones where `self > other` (false for NaN), else zero.
    fn greater(self, other: Self) -> Self;
    /// All ones where `self == other`, else zero.
    fn equal(self, other: Self) -> Self;
    /// `if self > other { self } else { other }` per lane.
    fn max(self, other: Self) -> Self;
    /// `if self < other { self } else { other }` per lane.
    fn min(self, other: Self) -> Self;
    /// Per lane, `if_set` where `self`'s sign bit is set, else `if_clear`.
    fn select(self, if_set: Self, if_clear: Self) -> Self;
    /// The lanes' sign bits, lane k at bit k.
    fn signs(self) -> u32;
    /// The sum of the lanes, in the same order in every implementation.
    #[inline(always)]
    fn sum(self) -> f64 {
        let mut values = [0.0; 32];
        self.store(&mut values);
        let lanes = &values[..Self::ALL.count_ones() as usize];
        lanes.iter().fold(0.0, |sum, value| sum + value)
    }
}

/// `[f(0), f(1), f(2), f(3)]`, always inlined: in `std::array::from_fn` the
/// closure may stay a call, and an AVX2 instruction inside it a call too.
#[inline(always)]
pub(super) fn four<T>(f: impl Fn(usize) -> T) -> [T; 4] {
    [f(0), f(1), f(2), f(3)]
}

/// [`four`] for six.
#[inline(always)]
pub(super) fn six<T>(f: impl Fn(usize) -> T) -> [T; 6] {
    [f(0), f(1), f(2), f(3), f(4), f(5)]
}

/// Bit patterns as lanes, for masks and the hit key's code.
#[inline(always)]
pub(super) fn splat_bits<V: Lanes>(bits: u64) -> V {
    V::splat(f64::from_bits(bits))
}

/// The portable lanes.
#[derive(Clone, Copy, Debug)]
pub(super) struct Portable([f64; 4]);

impl Portable {
    #[cfg(test)]
    pub(super) fn lane(self, k: usize) -> f64 {
        self.0[k]
    }

    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> Self {
        Self(four(|k| f(self.0[k])))
    }

    #[inline(always)]
    fn zip(self, other: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        Self(four(|k| f(self.0[k], other.0[k])))
    }

    #[inline(always)]
    fn bits(self, other: Self, f: impl Fn(u64, u64) -> u64) -> Self {
        self.zip(other, |a, b| f64::from_bits(f(a.to_bits(), b.to_bits())))
    }
}

impl Lanes for Portable {
    const ALL: u32 = 0b1111;
    #[inline(always)]
    fn splat(value: f64) -> Self {
        Self([value; 4])
    }
    #[inline(always)]
    fn load(values: &[f64]) -> Self {
        Self(four(|k| values[k]))
    }
    #[inline(always)]
    fn store(self, values: &mut [f64]) {
        values[..4].copy_from_slice(&self.0);
    }
    #[inline(always)]
    fn add(self, other: Self) -> Self {
        self.zip(other, |a, b| a + b)
    }
    #[inline(always)]
    fn sub(self, other: Self) -> Self {
        self.zip(other, |a, b| a - b)
    }
    #[inline(always)]
    fn mul(self, other: Self) -> Self {
        self.zip(other, |a, b| a * b)
    }
    #[inline(always)]
    fn div(self, other: Self) -> Self {
        self.zip(other, |a, b| a / b)
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        Self(four(|k| self.0[k].mul_add(a.0[k], b.0[k])))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(f64::sqrt)
    }
    #[inline(always)]
    fn and(self, other: Self) -> Self {
        self.bits(other, |a, b| a & b)
    }
    #[inline(always)]
    fn or(self, other: Self) -> Self {
        self.bits(other, |a, b| a | b)
    }
    #[inline(always)]
    fn and_not(self, other: Self) -> Self {
        self.bits(other, |a, b| !a & b)
    }
    #[inline(always)]
    fn xor(self, other: Self) -> Self {
        self.bits(other, |a, b| a ^ b)
    }
    #[inline(always)]
    fn greater(self, other: Self) -> Self {
        self.zip(other, |a, b| f64::from_bits(if a > b { !0 } else { 0 }))
    }
    #[inline(always)]
    fn equal(self, other: Self) -> Self {
        self.zip(other, |a, b| f64::from_bits(if a == b { !0 } else { 0 }))
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        self.zip(other, |a, b| if a > b { a } else { b })
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        self.zip(other, |a, b| if a < b { a } else { b })
    }
    #[inline(always)]
    fn select(self, if_set: Self, if_clear: Self) -> Self {
        Self(four(|k| {
            if self.0[k].is_sign_negative() {
                if_set.0[k]
            } else {
                if_clear.0[k]
            }
        }))
    }
    #[inline(always)]
    fn signs(self) -> u32 {
        (0..4).fold(0, |bits, k| {
            bits | (u32::from(self.0[k].is_sign_negative()) << k)
        })
    }
}

/// Two groups of lanes side by side: the kernel's long chains through a square root
/// and a division then run two at a time. Loads and stores take the halves from
/// and to consecutive groups; the kernel makes pairs of other groups itself.
#[derive(Clone, Copy, Debug)]
pub(super) struct Pair<V>(pub(super) V, pub(super) V);

impl<V: Lanes> Pair<V> {
    #[inline(always)]
    fn both(self, other: Self, f: impl Fn(V, V) -> V) -> Self {
        Self(f(self.0, other.0), f(self.1, other.1))
    }
}

impl<V: Lanes> Lanes for Pair<V> {
    const ALL: u32 = V::ALL | (V::ALL << V::ALL.count_ones());
    #[inline(always)]
    fn splat(value: f64) -> Self {
        Self(V::splat(value), V::splat(value))
    }
    #[inline(always)]
    fn load(values: &[f64]) -> Self {
        let half = V::ALL.count_ones() as usize;
        Self(V::load(values), V::load(&values[half..]))
    }
    #[inline(always)]
    fn store(self, values: &mut [f64]) {
        let half = V::ALL.count_ones() as usize;
        self.0.store(values);
        self.1.store(&mut values[half..]);
    }
    #[inline(always)]
    fn add(self, other: Self) -> Self {
        self.both(other, V::add)
    }
    #[inline(always)]
    fn sub(self, other: Self) -> Self {
        self.both(other, V::sub)
    }
    #[inline(always)]
    fn mul(self, other: Self) -> Self {
        self.both(other, V::mul)
    }
    #[inline(always)]
    fn div(self, other: Self) -> Self {
        self.both(other, V::div)
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        Self(self.0.mul_add(a.0, b.0), self.1.mul_add(a.1, b.1))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(self.0.sqrt(), self.1.sqrt())
    }
    #[inline(always)]
    fn and(self, other: Self) -> Self {
        self.both(other, V::and)
    }
    #[inline(always)]
    fn or(self, other: Self) -> Self {
        self.both(other, V::or)
    }
    #[inline(always)]
    fn and_not(self, other: Self) -> Self {
        self.both(other, V::and_not)
    }
    #[inline(always)]
    fn xor(self, other: Self) -> Self {
        self.both(other, V::xor)
    }
    #[inline(always)]
    fn greater(self, other: Self) -> Self {
        self.both(other, V::greater)
    }
    #[inline(always)]
    fn equal(self, other: Self) -> Self {
        self.both(other, V::equal)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        self.both(other, V::max)
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        self.both(other, V::min)
    }
    #[inline(always)]
    fn select(self, if_set: Self, if_clear: Self) -> Self {
        Self(
            self.0.select(if_set.0, if_clear.0),
            self.1.select(if_set.1, if_clear.1),
        )
    }
    #[inline(always)]
    fn signs(self) -> u32 {
        self.0.signs() | (self.1.signs() << V::ALL.count_ones())
    }
}

#[cfg(target_arch = "x86_64")]
pub(super) use avx2::Avx2;

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::Lanes;
    use std::arch::x86_64::*;

    /// Four lanes in an AVX2 register. Only ever made inside functions compiled
    /// for AVX2 and FMA, after checking that the CPU has them.
    #[derive(Clone, Copy, Debug)]
    pub(in super::super) struct Avx2(__m256d);

    // SAFETY (every method): an `Avx2` is only used where AVX2 and FMA are
    // available (see the type's doc); loads and stores are unaligned and checked
    // against the slice's length.
    impl Lanes for Avx2 {
        const ALL: u32 = 0b1111;
        #[inline(always)]
        fn splat(value: f64) -> Self {
            Self(unsafe { _mm256_set1_pd(value) })
        }
        #[inline(always)]
        fn load(values: &[f64]) -> Self {
            let values = &values[..4];
            Self(unsafe { _mm256_loadu_pd(values.as_ptr()) })
        }
        #[inline(always)]
        fn store(self, values: &mut [f64]) {
            let values = &mut values[..4];
            unsafe { _mm256_storeu_pd(values.as_mut_ptr(), self.0) }
        }
        #[inline(always)]
        fn add(self, other: Self) -> Self {
            Self(unsafe { _mm256_add_pd(self.0, other.0) })
        }
        #[inline(always)]
        fn sub(self, other: Self) -> Self {
            Self(unsafe { _mm256_sub_pd(self.0, other.0) })
        }
        #[inline(always)]
        fn mul(self, other: Self) -> Self {
            Self(unsafe { _mm256_mul_pd(self.0, other.0) })
        }
        #[inline(always)]
        fn div(self, other: Self) -> Self {
            Self(unsafe { _mm256_div_pd(self.0, other.0) })
        }
        #[inline(always)]
        fn mul_add(self, a: Self, b: Self) -> Self {
            Self(unsafe { _mm256_fmadd_pd(self.0, a.0, b.0) })
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            Self(unsafe { _mm256_sqrt_pd(self.0) })
        }
        #[inline(always)]
        fn and(self, other: Self) -> Self {
            Self(unsafe { _mm256_and_pd(self.0, other.0) })
        }
        #[inline(always)]
        fn or(self, other: Self) -> Self {
            Self(unsafe { _mm256_or_pd(self.0, other.0) })
        }
        #[inline(always)]
        fn and_not(self, other: Self) -> Self {
            Self(unsafe { _mm256_andnot_pd(self.0, other.0) })
        }
        #[inline(always)]
        fn xor(self, other: Self) -> Self {
            Self(unsafe { _mm256_xor_pd(self.0, other.0) })
        }
        #[inline(always)]
        fn greater(self, other: Self) -> Self {
            Self(unsafe { _mm256_cmp_pd::<_CMP_GT_OQ>(self.0, other.0) })
        }
        #[inline(always)]
        fn equal(self, other: Self) -> Self {
            Self(unsafe { _mm256_cmp_pd::<_CMP_EQ_OQ>(self.0, other.0) })
        }
        #[inline(always)]
        fn max(self, other: Self) -> Self {
            // max_pd(a, b) is `if a > b { a } else { b }`.
            Self(unsafe { _mm256_max_pd(self.0, other.0) })
        }
        #[inline(always)]
        fn min(self, other: Self) -> Self {
            // min_pd(a, b) is `if a < b { a } else { b }`.
            Self(unsafe { _mm256_min_pd(self.0, other.0) })
        }
        #[inline(always)]
        fn select(self, if_set: Self, if_clear: Self) -> Self {
            Self(unsafe { _mm256_blendv_pd(if_clear.0, if_set.0, self.0) })
        }
        #[inline(always)]
        fn signs(self) -> u32 {
            unsafe { _mm256_movemask_pd(self.0) as u32 }
        }
    }
}
