//! One statement of a formula for a single value and for SIMD lanes.
//!
//! The special functions, the microfacet terms and their sampling are
//! written once, generic over [`Real`], and run on `f32` in the scalar
//! plugin methods and on [`F32x4`] or [`F32x8`] (SSE2 lanes on baseline
//! x86-64, from the `wide` crate) in the batched ones. Both execute the
//! same IEEE operations in the same order, so a lane's result is bit for
//! bit the scalar one: special cases are selected lane by lane (and
//! returned early only where they cover every lane, which for `f32` is the
//! scalar branch), and nothing is fused into an `fma`. [`V3`] does the
//! same for 3-vectors, in glam's order of operations.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

use glam::Vec3;
use wide::{f32x4, f32x8, i32x4, i32x8};

/// Four f32 lanes.
pub type F32x4 = f32x4;

/// Eight f32 lanes (two SSE2 halves without `-C target-cpu`).
pub type F32x8 = f32x8;

/// A floating-point value or a vector of lanes, with the operations the
/// generic formulas use. Comparisons give a mask; [`Real::select`] picks
/// lane by lane.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    type Mask: Copy
        + BitAnd<Output = Self::Mask>
        + BitOr<Output = Self::Mask>
        + Not<Output = Self::Mask>;
    /// The lanes as an array, lane 0 first.
    type Array: Copy + AsRef<[f32]>;

    /// How many lanes.
    const LANES: usize;

    fn splat(v: f32) -> Self;
    /// Lane `i` from `f(i)`.
    fn from_fn(f: impl FnMut(usize) -> f32) -> Self;
    fn to_array(self) -> Self::Array;
    /// Lane `i` (for reading a few; [`Real::to_array`] for all).
    fn lane(self, i: usize) -> f32;
    /// Bit `i` set where lane `i` of `mask` holds.
    fn bitmask(mask: Self::Mask) -> u32;
    /// `b` in every lane.
    fn mask_splat(b: bool) -> Self::Mask;
    /// The mask that holds in lane `i` where bit `i` of `bits` is set.
    fn mask_from_bits(bits: u32) -> Self::Mask;
    fn sqrt(self) -> Self;
    fn abs(self) -> Self;
    /// The magnitude of `self` with the sign bit of `sign`.
    fn copysign(self, sign: Self) -> Self;
    fn lt(self, o: Self) -> Self::Mask;
    fn le(self, o: Self) -> Self::Mask;
    fn gt(self, o: Self) -> Self::Mask;
    fn ge(self, o: Self) -> Self::Mask;
    fn eq(self, o: Self) -> Self::Mask;
    /// Lanes that are NaN.
    fn is_nan(self) -> Self::Mask;
    /// `if_true` where `mask` holds, else `if_false`.
    fn select(mask: Self::Mask, if_true: Self, if_false: Self) -> Self;
    /// Whether `mask` holds in every lane: where a special case covers all
    /// lanes, the formula returns it early, as scalar code branches.
    fn all(mask: Self::Mask) -> bool;
    /// `self * 2^k` for integral `k` in `[-254, 254]`, in two steps of
    /// `2^(k/2)` so that a subnormal result needs no branch.
    fn mul_pow2(self, k: Self) -> Self;
    /// `(e, m)` with `self = 2^e m`, `e` integral and `m` in `[1, 2)`, for
    /// positive normal `self`: its exponent and significand fields.
    fn exponent_significand(self) -> (Self, Self);
    /// Whether bit `bit` of the two's complement of the integral `self`
    /// (`|self| < 2^31`) is set.
    fn int_bit(self, bit: u32) -> Self::Mask;
    /// `max(self, o)` for non-NaN `o`; NaN lanes of `self` stay NaN.
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        Self::select(self.lt(o), o, self)
    }
    /// `min(self, o)` for non-NaN `o`; NaN lanes of `self` stay NaN.
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        Self::select(self.gt(o), o, self)
    }
}

/// `2^k` for integer `k` in `[-126, 127]`, from its exponent bits.
#[inline(always)]
fn pow2i(k: i32) -> f32 {
    f32::from_bits(((k + 127) as u32) << 23)
}

impl Real for f32 {
    type Mask = bool;
    type Array = [f32; 1];
    const LANES: usize = 1;

    #[inline(always)]
    fn splat(v: f32) -> Self {
        v
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> f32) -> Self {
        f(0)
    }
    #[inline(always)]
    fn to_array(self) -> [f32; 1] {
        [self]
    }
    #[inline(always)]
    fn lane(self, _i: usize) -> f32 {
        self
    }
    #[inline(always)]
    fn bitmask(mask: bool) -> u32 {
        mask as u32
    }
    #[inline(always)]
    fn mask_splat(b: bool) -> bool {
        b
    }
    #[inline(always)]
    fn mask_from_bits(bits: u32) -> bool {
        bits & 1 != 0
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f32::abs(self)
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        f32::copysign(self, sign)
    }
    #[inline(always)]
    fn lt(self, o: Self) -> bool {
        self < o
    }
    #[inline(always)]
    fn le(self, o: Self) -> bool {
        self <= o
    }
    #[inline(always)]
    fn gt(self, o: Self) -> bool {
        self > o
    }
    #[inline(always)]
    fn ge(self, o: Self) -> bool {
        self >= o
    }
    #[inline(always)]
    fn eq(self, o: Self) -> bool {
        self == o
    }
    #[inline(always)]
    fn is_nan(self) -> bool {
        f32::is_nan(self)
    }
    #[inline(always)]
    fn select(mask: bool, if_true: Self, if_false: Self) -> Self {
        if mask {
            if_true
        } else {
            if_false
        }
    }
    #[inline(always)]
    fn all(mask: bool) -> bool {
        mask
    }
    #[inline(always)]
    fn mul_pow2(self, k: Self) -> Self {
        let k = k as i32;
        let half = k >> 1;
        self * pow2i(half) * pow2i(k - half)
    }
    #[inline(always)]
    fn exponent_significand(self) -> (Self, Self) {
        let bits = self.to_bits();
        let e = ((bits >> 23) as i32 - 127) as f32;
        (e, f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000))
    }
    #[inline(always)]
    fn int_bit(self, bit: u32) -> bool {
        (self as i32 >> bit) & 1 != 0
    }
}

/// [`Real`] for a `wide` vector type and its integer twin; the bodies are
/// the same for every width.
macro_rules! real_lanes {
    ($f:ident, $i:ident, $from_int:ident, $n:literal, [$($lane:literal),*]) => {
        impl Real for $f {
            type Mask = $f;
            type Array = [f32; $n];
            const LANES: usize = $n;

            #[inline(always)]
            fn splat(v: f32) -> Self {
                $f::splat(v)
            }
            #[inline(always)]
            fn from_fn(mut f: impl FnMut(usize) -> f32) -> Self {
                $f::new([$(f($lane)),*])
            }
            #[inline(always)]
            fn to_array(self) -> [f32; $n] {
                $f::to_array(self)
            }
            #[inline(always)]
            fn lane(self, i: usize) -> f32 {
                self.as_array()[i]
            }
            #[inline(always)]
            fn bitmask(mask: Self) -> u32 {
                mask.to_bitmask()
            }
            #[inline(always)]
            fn mask_splat(b: bool) -> Self {
                $f::splat(0.0).simd_eq($f::splat(if b { 0.0 } else { 1.0 }))
            }
            #[inline(always)]
            fn mask_from_bits(bits: u32) -> Self {
                let lane_bits = $i::new(std::array::from_fn(|i| 1 << i));
                let set = (lane_bits & $i::splat(bits as i32)).simd_eq(lane_bits);
                wide::bytemuck::cast(set)
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                $f::sqrt(self)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                $f::abs(self)
            }
            #[inline(always)]
            fn copysign(self, sign: Self) -> Self {
                let sign_bit = $f::splat(-0.0);
                (self & !sign_bit) | (sign & sign_bit)
            }
            #[inline(always)]
            fn lt(self, o: Self) -> Self {
                self.simd_lt(o)
            }
            #[inline(always)]
            fn le(self, o: Self) -> Self {
                self.simd_le(o)
            }
            #[inline(always)]
            fn gt(self, o: Self) -> Self {
                self.simd_gt(o)
            }
            #[inline(always)]
            fn ge(self, o: Self) -> Self {
                self.simd_ge(o)
            }
            #[inline(always)]
            fn eq(self, o: Self) -> Self {
                self.simd_eq(o)
            }
            #[inline(always)]
            fn is_nan(self) -> Self {
                $f::is_nan(self)
            }
            #[inline(always)]
            fn select(mask: Self, if_true: Self, if_false: Self) -> Self {
                mask.select(if_true, if_false)
            }
            #[inline(always)]
            fn all(mask: Self) -> bool {
                mask.all()
            }
            #[inline(always)]
            fn mul_pow2(self, k: Self) -> Self {
                // An integral `k` in range converts exactly, as `as i32`
                // does (no NaN to care about).
                let k = k.fast_round_int();
                let half = k >> 1;
                let pow2 = |e: $i| -> $f { wide::bytemuck::cast((e + $i::splat(127)) << 23) };
                self * pow2(half) * pow2(k - half)
            }
            #[inline(always)]
            fn exponent_significand(self) -> (Self, Self) {
                let bits: $i = wide::bytemuck::cast(self);
                let e = $f::$from_int((bits >> 23) - $i::splat(127));
                let m = (bits & $i::splat(0x007f_ffff)) | $i::splat(0x3f80_0000);
                (e, wide::bytemuck::cast(m))
            }
            #[inline(always)]
            fn int_bit(self, bit: u32) -> Self {
                let set = ((self.fast_round_int() >> bit) & $i::splat(1)).simd_eq($i::splat(1));
                wide::bytemuck::cast(set)
            }
        }
    };
}

real_lanes!(f32x4, i32x4, from_i32x4, 4, [0, 1, 2, 3]);
real_lanes!(f32x8, i32x8, from_i32x8, 8, [0, 1, 2, 3, 4, 5, 6, 7]);

/// Lane `i` from `get(v[i])`, lanes past the end of `v` from `get(pad)`.
///
/// A full chunk takes one bounds check, so that the lanes go straight into
/// registers: built in a stack array, or with a check per lane, the
/// vector is stored lane by lane and read back whole, which stalls store
/// forwarding (measured: 3x the cost of the GGX terms it fed).
#[inline(always)]
pub fn load<F: Real, T: Copy>(v: &[T], pad: T, get: impl Fn(T) -> f32) -> F {
    match v.get(..F::LANES) {
        Some(v) => F::from_fn(|i| get(v[i])),
        None => F::from_fn(|i| get(v.get(i).copied().unwrap_or(pad))),
    }
}

/// A 3-vector of [`Real`]s: one vector, or one per lane. Its operations
/// are glam's `Vec3` ones in glam's order, so `V3<f32>` gives glam's bits
/// and each lane of `V3<F32x4>` the same.
#[derive(Debug, Clone, Copy)]
pub struct V3<F> {
    pub x: F,
    pub y: F,
    pub z: F,
}

impl<F: Real> V3<F> {
    #[inline(always)]
    pub fn new(x: F, y: F, z: F) -> Self {
        Self { x, y, z }
    }

    /// `v` in every lane.
    #[inline(always)]
    pub fn splat(v: Vec3) -> Self {
        Self::new(F::splat(v.x), F::splat(v.y), F::splat(v.z))
    }

    /// Lane `i` from `f(i)` (called once per lane and component: a
    /// look-up).
    #[inline(always)]
    pub fn from_fn(f: impl Fn(usize) -> Vec3) -> Self {
        Self::new(
            F::from_fn(|i| f(i).x),
            F::from_fn(|i| f(i).y),
            F::from_fn(|i| f(i).z),
        )
    }

    /// Lane `i` from `v[i]`, lanes past the end of `v` from `pad`.
    #[inline(always)]
    pub fn load(v: &[Vec3], pad: Vec3) -> Self {
        Self::new(
            load(v, pad, |v| v.x),
            load(v, pad, |v| v.y),
            load(v, pad, |v| v.z),
        )
    }

    /// Lane `i`.
    #[inline(always)]
    pub fn lane(self, i: usize) -> Vec3 {
        Vec3::new(self.x.lane(i), self.y.lane(i), self.z.lane(i))
    }

    #[inline(always)]
    pub fn dot(self, o: Self) -> F {
        (self.x * o.x) + (self.y * o.y) + (self.z * o.z)
    }

    #[inline(always)]
    pub fn length(self) -> F {
        self.dot(self).sqrt()
    }

    /// `self / |self|`, as glam's `normalize`: times the reciprocal.
    #[inline(always)]
    pub fn normalize(self) -> Self {
        self * (F::splat(1.0) / self.length())
    }

    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        Self::new(
            self.y * o.z - o.y * self.z,
            self.z * o.x - o.z * self.x,
            self.x * o.y - o.x * self.y,
        )
    }

    /// `if_true` where `mask` holds, else `if_false`, lane by lane.
    #[inline(always)]
    pub fn select(mask: F::Mask, if_true: Self, if_false: Self) -> Self {
        Self::new(
            F::select(mask, if_true.x, if_false.x),
            F::select(mask, if_true.y, if_false.y),
            F::select(mask, if_true.z, if_false.z),
        )
    }
}

impl<F: Real> Add for V3<F> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl<F: Real> Sub for V3<F> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

/// Each component times `s` (glam's `Vec3 * f32`).
impl<F: Real> Mul<F> for V3<F> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, s: F) -> Self {
        Self::new(self.x * s, self.y * s, self.z * s)
    }
}

/// Each component divided by `s` (glam's `Vec3 / f32`).
impl<F: Real> Div<F> for V3<F> {
    type Output = Self;
    #[inline(always)]
    fn div(self, s: F) -> Self {
        Self::new(self.x / s, self.y / s, self.z / s)
    }
}

impl From<Vec3> for V3<f32> {
    #[inline(always)]
    fn from(v: Vec3) -> Self {
        Self::new(v.x, v.y, v.z)
    }
}

impl From<V3<f32>> for Vec3 {
    #[inline(always)]
    fn from(v: V3<f32>) -> Self {
        Vec3::new(v.x, v.y, v.z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_scale_by_powers_of_two_as_the_scalar_does() {
        let x = F32x4::new([1.5, -3.0, 1e-20, 7.0]);
        for k in [-254.0, -150.0, -1.0, 0.0, 1.0, 100.0, 254.0] {
            let lanes = x.mul_pow2(F32x4::splat(k)).to_array();
            for (lane, &v) in lanes.iter().zip(&x.to_array()) {
                assert_eq!(lane.to_bits(), v.mul_pow2(k).to_bits(), "{v} 2^{k}");
            }
        }
    }

    #[test]
    fn select_and_comparisons_agree_lane_by_lane() {
        let a = F32x4::new([1.0, f32::NAN, -2.0, 0.0]);
        let b = F32x4::splat(0.0);
        let picked = F32x4::select(a.gt(b) | a.is_nan(), F32x4::splat(1.0), F32x4::splat(2.0));
        assert_eq!(picked.to_array(), [1.0, 1.0, 2.0, 2.0]);
        assert_eq!(Real::max(a, b).to_array()[2], 0.0);
        assert!(Real::max(a, b).to_array()[1].is_nan());
        assert_eq!(F32x4::bitmask(a.lt(b)), 0b0100);
        assert_eq!(F32x8::bitmask(F32x8::mask_splat(true)), 0xff);
        assert_eq!(F32x4::bitmask(F32x4::mask_splat(false)), 0);
        assert_eq!(
            F32x8::bitmask(F32x8::mask_from_bits(0b1010_0110)),
            0b1010_0110
        );
        assert!(f32::mask_from_bits(1) && !f32::mask_from_bits(2));
    }

    /// The bit-level operations give the scalar's bits in every lane, for
    /// both widths.
    #[test]
    fn bit_operations_agree_lane_by_lane() {
        let xs = [
            1.0f32,
            1.5,
            f32::MIN_POSITIVE,
            3.4e38,
            0.7,
            1e-20,
            123.456,
            2.0,
        ];
        let signs = [1.0f32, -1.0, -0.0, 0.0, 3.0, -2.0, 1.0, -1.0];
        let ints = [0.0f32, 1.0, 2.0, 3.0, -1.0, -2.0, -3.0, 4_194_301.0];
        let x8 = F32x8::new(xs);
        let (e, m) = x8.exponent_significand();
        let c = x8.copysign(F32x8::new(signs));
        for i in 0..8 {
            let (se, sm) = xs[i].exponent_significand();
            assert_eq!((e.lane(i), m.lane(i)), (se, sm), "{}", xs[i]);
            assert_eq!(c.lane(i).to_bits(), xs[i].copysign(signs[i]).to_bits());
            for bit in [0, 1] {
                let lane = F32x8::bitmask(F32x8::new(ints).int_bit(bit)) >> i & 1 != 0;
                assert_eq!(lane, ints[i].int_bit(bit), "bit {bit} of {}", ints[i]);
            }
        }
    }

    #[test]
    fn vectors_are_glams_bit_for_bit() {
        let a = Vec3::new(0.3, -1.7, 0.25);
        let b = Vec3::new(-2.0, 0.1, 9.5);
        let lanes = V3::<F32x4>::from_fn(|i| a * (i as f32 + 1.0));
        for i in 0..4 {
            let s = a * (i as f32 + 1.0);
            assert_eq!(lanes.normalize().lane(i), s.normalize());
            assert_eq!(lanes.cross(V3::splat(b)).lane(i), s.cross(b));
            assert_eq!(lanes.dot(V3::splat(b)).lane(i), s.dot(b));
            assert_eq!((lanes / F32x4::splat(3.0)).lane(i), s / 3.0);
            assert_eq!(
                (lanes * F32x4::splat(3.0) + lanes - V3::splat(b)).lane(i),
                s * 3.0 + s - b
            );
        }
        assert_eq!(Vec3::from(V3::from(a).normalize()), a.normalize());
    }
}
