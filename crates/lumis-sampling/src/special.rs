//! Special functions in single precision, for the hot paths of sampling and
//! evaluation: `exp`, `ln`, `erf`, `erfc`, `erf_inv`, the sine and
//! cosine of an angle in turns, and `atan2`.
//!
//! Each is a polynomial or rational approximation evaluated in f32 with
//! plain multiplies and adds (no `fma`, which baseline x86-64 would call
//! out of line), inlinable and branch-light, so that it costs a few
//! nanoseconds where glibc's double-precision calls cost tens. Each is
//! generic over [`Real`]: on `f32`, and on SIMD lanes with each lane's
//! result bit for bit the scalar one (see [`crate::real`]). Each states
//! its maximum error over its whole domain; the tests below measure it
//! against the double-precision functions of the standard library (and
//! `libm`'s `erf`/`erfc`) on a dense sweep of every binade, and fail if it
//! grows. Errors are in ulps of the exact result rounded to f32, or
//! absolute where the result crosses zero.

use std::f32::consts::{FRAC_2_SQRT_PI, FRAC_PI_2, FRAC_PI_4, LOG2_E, PI};

use crate::real::Real;

/// Adding and subtracting `1.5 * 2^23` rounds an f32 of magnitude below
/// `2^22` to the nearest integer (ties to even): `round()` would be a
/// library call on baseline x86-64, which lacks `roundss`.
const ROUND_MAGIC: f32 = 12_582_912.0;

/// `ln 2` split for Cody and Waite's argument reduction: the high part has
/// 9 significant bits, so `k * LN2_HI` is exact for `|k| < 2^15`.
const LN2_HI: f32 = 355.0 / 512.0;
const LN2_LO: f32 = -2.121_944_4e-4;

/// `1 / sqrt(pi)`, the constant of the Gaussian and of `erf`'s derivative.
pub const FRAC_1_SQRT_PI: f32 = 0.564_189_6;

/// `e^x`. Maximum error 1 ulp (measured: see the tests); overflows to
/// infinity above `ln(f32::MAX)` and flushes to zero below `-103.98`, with
/// gradual underflow in between.
///
/// `x = k ln 2 + r` with `|r| <= ln 2 / 2` (Cody and Waite 1980, section
/// 6), `e^r` by its Taylor polynomial of degree 7 (truncation error
/// `r^8 / 8! < 6e-9`), scaled by `2^k` in two steps so that subnormal
/// results need no branch.
#[inline]
pub fn exp<F: Real>(x: F) -> F {
    const C: [f32; 7] = [
        1.0 / 2.0,
        1.0 / 6.0,
        1.0 / 24.0,
        1.0 / 120.0,
        1.0 / 720.0,
        1.0 / 5040.0,
        1.0 / 40_320.0,
    ];
    const OVERFLOW: f32 = 88.722_84;
    const UNDERFLOW: f32 = -103.98;
    let s = F::splat;
    let special = |y: F| {
        let y = F::select(x.gt(s(OVERFLOW)), s(f32::INFINITY), y);
        let y = F::select(x.lt(s(UNDERFLOW)), s(0.0), y);
        F::select(x.is_nan(), x, y)
    };
    let out_of_range = x.is_nan() | x.gt(s(OVERFLOW)) | x.lt(s(UNDERFLOW));
    if F::all(out_of_range) {
        return special(x);
    }
    // Overflow, underflow and NaN lanes are worked on as 0 and selected at
    // the end: clamped to the range ends instead, an underflowing lane
    // would scale to a subnormal, and each SIMD operation on one costs a
    // microcode assist of ~150 cycles (they made `eval_batch` slower than
    // the scalar loop on narrow lobes).
    let xc = F::select(out_of_range, s(0.0), x);
    let k = (xc * s(LOG2_E) + s(ROUND_MAGIC)) - s(ROUND_MAGIC);
    let r = (xc - k * s(LN2_HI)) - k * s(LN2_LO);
    let mut p = s(C[6]);
    for &c in C[..6].iter().rev() {
        p = s(c) + r * p;
    }
    let er = s(1.0) + (r + r * r * p);
    special(er.mul_pow2(k))
}

/// The natural logarithm. Maximum error 1 ulp (measured); `-inf` at 0,
/// NaN below 0, `+inf` at `+inf`; subnormals are handled.
///
/// `x = 2^e (1 + f)` with `1 + f` in `[sqrt(1/2), sqrt(2))`, and
/// `ln(1 + f) = 2 atanh(s)`, `s = f / (2 + f)`, `|s| <= 0.1716`, by the odd
/// series `2 (s + s^3/3 + ... + s^9/9)` (truncation `2 s^11 / 11 < 4e-10`),
/// arranged as in fdlibm's `log` so that the exact `f` is added last:
/// `ln(1 + f) = f - (f^2/2 - s (f^2/2 + R))`, `R = 2 s^2/3 + ... + 2
/// s^8/9`.
#[inline]
pub fn ln<F: Real>(x: F) -> F {
    let c = F::splat;
    let in_domain = x.gt(c(0.0)) & x.lt(c(f32::INFINITY));
    let special = || {
        let y = F::select(x.eq(c(f32::INFINITY)), x, c(f32::NAN));
        F::select(x.eq(c(0.0)), c(f32::NEG_INFINITY), y)
    };
    if F::all(!in_domain) {
        return special();
    }
    // Lanes outside the domain are worked on as 1 and selected at the end.
    let x = F::select(in_domain, x, c(1.0));
    // Subnormals scaled by 2^23 into the normal range first.
    let subnormal = x.lt(c(f32::MIN_POSITIVE));
    let x = F::select(subnormal, x * c(8_388_608.0), x);
    let (e, m) = x.exponent_significand();
    let e = F::select(subnormal, e - c(23.0), e);
    let above = m.gt(c(std::f32::consts::SQRT_2));
    let m = F::select(above, m * c(0.5), m);
    let e = F::select(above, e + c(1.0), e);
    let f = m - c(1.0);
    let s = f / (c(2.0) + f);
    let s2 = s * s;
    let r = s2 * (c(2.0 / 3.0) + s2 * (c(2.0 / 5.0) + s2 * (c(2.0 / 7.0) + s2 * c(2.0 / 9.0))));
    let half_f2 = c(0.5) * f * f;
    let y = e * c(LN2_HI) + ((f - (half_f2 - s * (half_f2 + r))) + e * c(LN2_LO));
    F::select(in_domain, y, special())
}

/// The complementary error function `erfc(x) = 1 - erf(x)`. Maximum
/// relative error 5e-7 for `x >= 0`, absolute error 6e-7 for `x < 0`
/// (measured); zero beyond `x = 10.05`.
///
/// The Chebyshev fit `erfc(z) = t exp(-z^2 + P(t))`, `t = 1/(1 + z/2)`, of
/// Press et al., "Numerical Recipes" (2nd ed., section 6.2; fractional
/// error below 1.2e-7 in exact arithmetic). `z^2` is split into its
/// rounded value and the rounding error so that the exponent keeps its
/// precision where `z^2` is large.
#[inline]
pub fn erfc<F: Real>(x: F) -> F {
    const P: [f32; 10] = [
        -1.265_512_2,
        1.000_023_7,
        0.374_091_96,
        0.096_784_18,
        -0.186_288_06,
        0.278_868_07,
        -1.135_204,
        1.488_515_9,
        -0.822_152_23,
        0.170_872_77,
    ];
    let s = F::splat;
    let z = x.abs();
    // Beyond 10.06, below the smallest subnormal (and no NaN from an
    // infinite z).
    let far = z.gt(s(10.06));
    let sided = |r: F| F::select(x.ge(s(0.0)), r, s(2.0) - r);
    if F::all(far) {
        return sided(s(0.0));
    }
    let t = s(1.0) / (s(1.0) + s(0.5) * z);
    let mut p = s(P[9]);
    for &c in P[..9].iter().rev() {
        p = s(c) + t * p;
    }
    // The exponent p - z^2 to twice f32's precision: e^(a + b) = e^a (1 +
    // b) for the rounding errors b of the square and of the difference.
    let z2 = z * z;
    let z2_err = two_product_error(z, z, z2);
    let (exponent, exponent_err) = two_sum(p, -z2);
    let r = t * exp(exponent) * (s(1.0) + (exponent_err - z2_err));
    sided(F::select(far, s(0.0), r))
}

/// `a * b - p` for `p = fl(a * b)`, exactly (Dekker 1971, by Veltkamp's
/// splitting; no `fma`).
#[inline(always)]
fn two_product_error<F: Real>(a: F, b: F, p: F) -> F {
    let split = |v: F| {
        let c = F::splat(4097.0) * v; // 2^12 + 1
        let hi = c - (c - v);
        (hi, v - hi)
    };
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    ((ah * bh - p) + ah * bl + al * bh) + al * bl
}

/// `(s, e)` with `s = fl(a + b)` and `a + b = s + e` exactly (Knuth's
/// two-sum, TAOCP vol. 2, 4.2.2).
#[inline(always)]
fn two_sum<F: Real>(a: F, b: F) -> (F, F) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// The error function. Maximum error 2 ulp (measured).
///
/// Below `|x| = 1` its Maclaurin series `2/sqrt(pi) sum (-1)^n x^(2n+1) /
/// (n! (2n + 1))` to `n = 10` (truncation below `2e-9`), which keeps the
/// relative precision at tiny `x`; from 1 on, `1 - erfc(|x|)`, whose error
/// is then below an ulp of `erf`.
#[inline]
pub fn erf<F: Real>(x: F) -> F {
    /// `2/sqrt(pi) - 1`, so that `x` is added exactly.
    const FRAC_2_SQRT_PI_MINUS_1: f32 = 0.128_379_17;
    /// `2/sqrt(pi) (-1)^n / (n! (2n + 1))`.
    const T: [f32; 11] = [
        FRAC_2_SQRT_PI,
        -0.376_126_4,
        0.112_837_92,
        -0.026_866_17,
        5.223_977_6e-3,
        -8.548_327e-4,
        1.205_533_3e-4,
        -1.492_565e-5,
        1.646_211_4e-6,
        -1.636_584_5e-7,
        1.480_719_3e-8,
    ];
    let s = F::splat;
    let z = x.abs();
    let series = || {
        // x + x (T[0] - 1 + x^2 (...)): the leading term exact.
        let x2 = x * x;
        let mut p = s(T[10]);
        for &c in T[1..10].iter().rev() {
            p = s(c) + x2 * p;
        }
        x + x * (s(FRAC_2_SQRT_PI_MINUS_1) + x2 * p)
    };
    let complement = || (s(1.0) - erfc(z)).copysign(x);
    let small = z.lt(s(1.0));
    if F::all(small) {
        series()
    } else if F::all(!small) {
        complement()
    } else {
        F::select(small, series(), complement())
    }
}

/// The inverse error function on `[-1, 1]`; `+-inf` at `+-1`, NaN outside.
/// Maximum relative error 5e-7 (measured, against the inverse of the
/// double-precision `erf`).
///
/// Giles, "Approximating the erfinv function" (GPU Computing Gems Jade
/// Edition, 2011), single-precision version: with `w = -ln(1 - y^2)`, a
/// polynomial in `w - 5/2` for `w < 5` and in `sqrt(w) - 3` beyond, times
/// `y`. `1 - y^2` is formed as `(1 - y)(1 + y)`, exact enough near `+-1`.
#[inline]
pub fn erf_inv<F: Real>(y: F) -> F {
    const CENTRAL: [f32; 9] = [
        2.810_226_4e-8,
        3.432_739_4e-7,
        -3.523_387_7e-6,
        -4.391_506_5e-6,
        2.185_808_7e-4,
        -1.253_725e-3,
        -4.177_681_6e-3,
        0.246_640_73,
        1.501_409_4,
    ];
    const TAIL: [f32; 9] = [
        -2.002_142_6e-4,
        1.009_505_6e-4,
        1.349_343_2e-3,
        -3.673_428_4e-3,
        5.739_507_7e-3,
        -7.622_461_3e-3,
        9.438_870_5e-3,
        1.001_674,
        2.832_976_8,
    ];
    let s = F::splat;
    let inside = y.abs().lt(s(1.0));
    let special = || {
        F::select(
            y.abs().eq(s(1.0)),
            s(f32::INFINITY).copysign(y),
            s(f32::NAN),
        )
    };
    if F::all(!inside) {
        return special();
    }
    // Lanes at or beyond +-1 are worked on as 0 and selected at the end.
    let y = F::select(inside, y, s(0.0));
    let w = -ln((s(1.0) - y) * (s(1.0) + y));
    let polynomial = |coefficient: &dyn Fn(usize) -> F, t: F| {
        let mut p = coefficient(0);
        for i in 1..9 {
            p = coefficient(i) + p * t;
        }
        p
    };
    let central = w.lt(s(5.0));
    let p = if F::all(central) {
        polynomial(&|i| s(CENTRAL[i]), w - s(2.5))
    } else if F::all(!central) {
        polynomial(&|i| s(TAIL[i]), w.sqrt() - s(3.0))
    } else {
        // Each lane with its own branch's coefficients and variable.
        let t = F::select(central, w - s(2.5), w.sqrt() - s(3.0));
        polynomial(&|i| F::select(central, s(CENTRAL[i]), s(TAIL[i])), t)
    };
    F::select(inside, p * y, special())
}

/// `(sin x, cos x)` for `|x| <= pi/4`: the Taylor polynomials of degree 9
/// and 10 in Horner form. Their truncation errors at pi/4 are `x^11/11! <
/// 2e-9` and `x^12/12! < 2e-10`, far below f32's half ulp, so the result is
/// within 2 ulp of the exact one (tested).
#[inline]
pub fn sin_cos_quarter_turn<F: Real>(x: F) -> (F, F) {
    const S: [f32; 4] = [-1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0, 1.0 / 362_880.0];
    const C: [f32; 5] = [
        -1.0 / 2.0,
        1.0 / 24.0,
        -1.0 / 720.0,
        1.0 / 40_320.0,
        -1.0 / 3_628_800.0,
    ];
    let s = F::splat;
    let x2 = x * x;
    let sin = x + x * x2 * (s(S[0]) + x2 * (s(S[1]) + x2 * (s(S[2]) + x2 * s(S[3]))));
    let cos =
        s(1.0) + x2 * (s(C[0]) + x2 * (s(C[1]) + x2 * (s(C[2]) + x2 * (s(C[3]) + x2 * s(C[4])))));
    (sin, cos)
}

/// `(sin 2 pi t, cos 2 pi t)` for an angle of `t` turns, `|t| < 2^20`: the
/// azimuth of nearly every warp, `phi = 2 pi u`. Maximum error 3 ulp, or
/// `3e-8` absolute near the zeros (measured).
///
/// The reduction is exact in turns: with `q` the nearest quarter turn,
/// `t - q/4` is computed without rounding (Sterbenz), leaving `|x| <=
/// pi/4` for [`sin_cos_quarter_turn`], then a rotation by `q` quarters.
#[inline]
pub fn sin_cos_turns<F: Real>(t: F) -> (F, F) {
    let k = F::splat;
    let quarters = (k(4.0) * t + k(ROUND_MAGIC)) - k(ROUND_MAGIC);
    let x = (t - k(0.25) * quarters) * k(4.0 * FRAC_PI_2);
    let (s, c) = sin_cos_quarter_turn(x);
    // Quarter q mod 4 = 0, 1, 2, 3: (s, c), (c, -s), (-s, -c), (-c, s):
    // an odd q swaps, bit 1 of q negates.
    let odd = quarters.int_bit(0);
    let (s, c) = (F::select(odd, c, s), F::select(odd, -s, c));
    let half_turn = quarters.int_bit(1);
    (F::select(half_turn, -s, s), F::select(half_turn, -c, c))
}

/// The angle of the point `(x, y)` from the `+x` axis, in `[-pi, pi]`, as
/// `f32::atan2` for finite arguments (`atan2(+-0, x < 0) = +-pi`, and 0 at
/// the origin), NaN if either is NaN. Maximum error 3 ulp (measured: 2.8 just above the
/// reduction's threshold).
///
/// The smaller of `|x|, |y|` over the larger is a tangent in `[0, 1]`;
/// above `tan(pi/8)` it is reduced by `atan t = pi/4 + atan((t - 1) / (t +
/// 1))`, both forms computed with a single division, and `atan` on
/// `|t| <= tan(pi/8)` is Cephes's `atanf` polynomial (Moshier, "Methods
/// and Programs for Mathematical Functions", 1989; relative error 2e-7 in
/// exact arithmetic). The octant is restored by `pi/2 - a`, `pi - a` and
/// the sign of `y`.
#[inline]
pub fn atan2<F: Real>(y: F, x: F) -> F {
    const P: [f32; 4] = [-0.333_329_5, 0.199_777_11, -0.138_776_85, 0.080_537_446];
    const TAN_PI_8: f32 = 0.414_213_57;
    let s = F::splat;
    let (ax, ay) = (x.abs(), y.abs());
    let (small, large) = (ax.min(ay), ax.max(ay));
    let reduced = small.gt(s(TAN_PI_8) * large);
    let numerator = F::select(reduced, small - large, small);
    let denominator = F::select(reduced, small + large, large);
    // The origin: 0 / 0 taken as 0.
    let t = F::select(denominator.eq(s(0.0)), s(0.0), numerator / denominator);
    let z = t * t;
    let p = s(P[0]) + z * (s(P[1]) + z * (s(P[2]) + z * s(P[3])));
    let a = F::select(reduced, s(FRAC_PI_4), s(0.0)) + (t + t * z * p);
    let a = F::select(ay.gt(ax), s(FRAC_PI_2) - a, a);
    let a = F::select(x.lt(s(0.0)), s(PI) - a, a);
    F::select(x.is_nan() | y.is_nan(), x + y, a.copysign(y))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::real::{F32x4, F32x8};

    /// The generic functions on SIMD lanes (four and eight) give the
    /// scalar results bit for bit, over every binade of both signs and the
    /// special values, each chunk mixing lanes that take different
    /// branches.
    #[test]
    fn lanes_match_the_scalar_functions_bit_for_bit() {
        let mut xs: Vec<f32> = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, -0.0]
            .into_iter()
            .chain([
                88.722_84,
                88.73,
                -103.98,
                -103.99,
                10.06,
                10.07,
                f32::MAX,
                f32::MIN_POSITIVE,
                f32::from_bits(1),
                1.0,
                -1.0,
                0.999_999_94,
                -0.999_999_94,
                0.25,
                0.5,
                0.75,
            ])
            .collect();
        xs.extend(sweep(1e-30, 200.0, 9_973));
        xs.extend(sweep(-1e-30, -200.0, 9_973));
        xs.extend(sweep(1e-40, 1.0, 99_991));
        xs.extend(sweep(-1e-40, -1.0, 99_991));
        check_lanes::<F32x4>(&xs);
        check_lanes::<F32x8>(&xs);
    }

    /// A scalar function, its value on the lanes, its name.
    type Case<'a, F> = (fn(f32) -> f32, F, &'a str);

    fn check_lanes<F: Real>(xs: &[f32]) {
        let same = |a: f32, b: f32| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
        for chunk in xs.chunks(F::LANES) {
            let lanes = F::from_fn(|i| chunk[i % chunk.len()]);
            let turns = |x: F| sin_cos_turns(x);
            let quarter = |x: F| sin_cos_quarter_turn(x * F::splat(1e-2));
            let angle = |x: F| atan2(x, F::splat(1.0) - x);
            let results: [Case<F>; 10] = [
                (exp::<f32>, exp(lanes), "exp"),
                (erfc::<f32>, erfc(lanes), "erfc"),
                (erf::<f32>, erf(lanes), "erf"),
                (erf_inv::<f32>, erf_inv(lanes), "erf_inv"),
                (ln::<f32>, ln(lanes), "ln"),
                (|x| atan2(x, 1.0 - x), angle(lanes), "atan2"),
                (|x| sin_cos_turns(x).0, turns(lanes).0, "sin turns"),
                (|x| sin_cos_turns(x).1, turns(lanes).1, "cos turns"),
                (
                    |x| sin_cos_quarter_turn(x * 1e-2).0,
                    quarter(lanes).0,
                    "sin",
                ),
                (
                    |x| sin_cos_quarter_turn(x * 1e-2).1,
                    quarter(lanes).1,
                    "cos",
                ),
            ];
            for (f, simd, name) in results {
                for (i, &x) in chunk.iter().enumerate() {
                    // Outside the documented domain |t| < 2^20 (or NaN).
                    let in_domain = x.abs() < 1_048_576.0;
                    if name.ends_with("turns") && !in_domain {
                        continue;
                    }
                    let lane = simd.lane(i);
                    assert!(
                        same(lane, f(x)),
                        "{name}({x}) on {} lanes: lane {lane}, scalar {}",
                        F::LANES,
                        f(x)
                    );
                }
            }
        }
    }

    /// Every `stride`-th f32 bit pattern in `[lo, hi]` (both finite, same
    /// sign), and the ends.
    fn sweep(lo: f32, hi: f32, stride: u32) -> impl Iterator<Item = f32> {
        let (a, b) = if lo.to_bits() <= hi.to_bits() {
            (lo.to_bits(), hi.to_bits())
        } else {
            (hi.to_bits(), lo.to_bits())
        };
        (a..=b)
            .step_by(stride as usize)
            .chain([b])
            .map(f32::from_bits)
    }

    /// Error of `got` in ulps of the exact value rounded to f32; for exact
    /// values below `floor` in magnitude, in ulps of `floor` (absolute).
    fn ulps(got: f32, exact: f64, floor: f64) -> f64 {
        let scale = (exact.abs().max(floor) as f32).abs();
        let ulp = f32::from_bits(scale.to_bits() + 1) - scale;
        (got as f64 - exact).abs() / ulp as f64
    }

    fn worst(
        xs: impl Iterator<Item = f32>,
        f: impl Fn(f32) -> (f32, f64),
        floor: f64,
    ) -> (f64, f32) {
        let mut worst = (0.0f64, 0.0f32);
        for x in xs {
            let (got, exact) = f(x);
            let e = ulps(got, exact, floor);
            assert!(!e.is_nan(), "x = {x}: got {got}, exact {exact}");
            if e > worst.0 {
                worst = (e, x);
            }
        }
        worst
    }

    #[test]
    fn exp_within_one_ulp_over_its_range() {
        let (e, at) = worst(
            sweep(-103.9, -f32::from_bits(1), 61),
            |x| (exp(x), (x as f64).exp()),
            f32::MIN_POSITIVE as f64,
        );
        assert!(e <= 1.0, "exp: {e} ulp at {at}");
        let (e, at) = worst(
            sweep(0.0, 88.72, 61),
            |x| (exp(x), (x as f64).exp()),
            f32::MIN_POSITIVE as f64,
        );
        assert!(e <= 1.0, "exp: {e} ulp at {at}");
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(89.0), f32::INFINITY);
        assert_eq!(exp(-104.0), 0.0);
        assert_eq!(exp(f32::NEG_INFINITY), 0.0);
        assert!(exp(f32::NAN).is_nan());
    }

    #[test]
    fn ln_within_one_ulp_over_its_domain() {
        let (e, at) = worst(
            sweep(f32::from_bits(1), f32::MAX, 61),
            |x| (ln(x), (x as f64).ln()),
            1e-30,
        );
        assert!(e <= 1.0, "ln: {e} ulp at {at}");
        assert_eq!(ln(1.0), 0.0);
        assert_eq!(ln(0.0), f32::NEG_INFINITY);
        assert_eq!(ln(f32::INFINITY), f32::INFINITY);
        assert!(ln(-1.0).is_nan() && ln(f32::NAN).is_nan());
    }

    #[test]
    fn erf_and_erfc_match_double_precision() {
        let (e, at) = worst(
            sweep(f32::from_bits(1), 10.0, 61),
            |x| (erf(x), libm::erf(x as f64)),
            1e-45,
        );
        assert!(e <= 2.0, "erf: {e} ulp at {at}");
        assert_eq!(erf(-0.75), -erf(0.75));
        // Relative error of erfc over [0, 10] (results down to 2e-45).
        let mut worst_rel = 0.0f64;
        for x in sweep(f32::from_bits(1), 10.0, 61) {
            let exact = libm::erfc(x as f64);
            let rel = ((erfc(x) as f64 - exact) / exact).abs();
            if exact > 1e-37 {
                worst_rel = worst_rel.max(rel);
            }
        }
        assert!(worst_rel <= 5e-7, "erfc: relative error {worst_rel}");
        // Negative arguments: absolute error of 2 - erfc(-x).
        for x in sweep(-10.0, -1e-30, 61) {
            let exact = libm::erfc(x as f64);
            let err = (erfc(x) as f64 - exact).abs();
            assert!(err <= 6e-7, "erfc({x}): error {err}");
        }
        assert_eq!(erfc(11.0), 0.0);
        assert_eq!(erfc(f32::INFINITY), 0.0);
        assert_eq!(erfc(f32::NEG_INFINITY), 2.0);
        assert_eq!(erf(f32::INFINITY), 1.0);
        assert!(erfc(f32::NAN).is_nan() && erf(f32::NAN).is_nan());
    }

    /// The double-precision inverse of `erf`, by bisection on `libm::erf`.
    fn erf_inv_f64(y: f64) -> f64 {
        let (mut lo, mut hi) = (-7.0f64, 7.0f64);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if libm::erf(mid) < y {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    #[test]
    fn erf_inv_matches_the_inverse_of_double_precision_erf() {
        let mut worst = (0.0f64, 0.0f32);
        // Results from 1e-37 on are normal numbers; below, subnormal
        // rounding alone is up to half of their spacing, 1.4e-45.
        for y in sweep(1e-37, 1.0 - f32::EPSILON / 2.0, 4099) {
            let exact = erf_inv_f64(y as f64);
            let rel = ((erf_inv(y) as f64 - exact) / exact).abs();
            if rel > worst.0 {
                worst = (rel, y);
            }
        }
        assert!(
            worst.0 <= 5e-7,
            "erf_inv: relative error {} at {}",
            worst.0,
            worst.1
        );
        assert_eq!(erf_inv(0.0), 0.0);
        assert_eq!(erf_inv(-0.5), -erf_inv(0.5));
        assert_eq!(erf_inv(1.0), f32::INFINITY);
        assert_eq!(erf_inv(-1.0), f32::NEG_INFINITY);
        assert!(erf_inv(1.5).is_nan());
    }

    #[test]
    fn quarter_turn_sin_cos_within_two_ulp() {
        let (e, at) = worst(
            sweep(f32::from_bits(1), std::f32::consts::FRAC_PI_4, 61),
            |x| (sin_cos_quarter_turn(x).0, (x as f64).sin()),
            1e-45,
        );
        assert!(e <= 2.0, "sin: {e} ulp at {at}");
        let (e, at) = worst(
            sweep(0.0, std::f32::consts::FRAC_PI_4, 61),
            |x| (sin_cos_quarter_turn(x).1, (x as f64).cos()),
            1e-45,
        );
        assert!(e <= 2.0, "cos: {e} ulp at {at}");
    }

    #[test]
    fn turns_sin_cos_over_whole_turns() {
        let two_pi = 2.0 * std::f64::consts::PI;
        for (lo, hi) in [(0.0f32, 1.0f32), (-1.0, -1e-30), (1.0, 64.0)] {
            let (e, at) = worst(
                sweep(lo, hi, 61),
                |t| (sin_cos_turns(t).0, (two_pi * t as f64).sin()),
                1e-7,
            );
            assert!(e <= 3.0, "sin 2 pi t: {e} ulp at t = {at}");
            let (e, at) = worst(
                sweep(lo, hi, 61),
                |t| (sin_cos_turns(t).1, (two_pi * t as f64).cos()),
                1e-7,
            );
            assert!(e <= 3.0, "cos 2 pi t: {e} ulp at t = {at}");
        }
        assert_eq!(sin_cos_turns(0.0), (0.0, 1.0));
        assert_eq!(sin_cos_turns(0.25), (1.0, 0.0));
    }

    #[test]
    fn atan2_within_three_ulp_around_the_circle_and_at_the_axes() {
        let mut worst = (0.0f64, 0.0f32, 0.0f32);
        let mut check = |y: f32, x: f32| {
            let exact = (y as f64).atan2(x as f64);
            let e = ulps(atan2(y, x), exact, 1e-45);
            assert!(!e.is_nan(), "atan2({y}, {x}) = {}", atan2(y, x));
            if e > worst.0 {
                worst = (e, y, x);
            }
        };
        // A million directions around the circle, both zeros of each axis.
        let n = 1_000_000;
        for k in 0..n {
            let a = (k as f64 + 0.5) / n as f64 * std::f64::consts::TAU;
            check(a.sin() as f32, a.cos() as f32);
        }
        // Tangents over every binade, in every octant: the axes and the
        // diagonals approached from both sides.
        for t in sweep(1e-30, 1e30, 4099) {
            for (sy, sx) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                check(sy * t, sx);
                check(sy, sx * t);
            }
        }
        assert!(
            worst.0 <= 3.0,
            "atan2: {} ulp at ({}, {})",
            worst.0,
            worst.1,
            worst.2
        );
        assert_eq!(atan2(0.0, 1.0), 0.0);
        assert_eq!(atan2(0.0, -1.0), PI);
        assert_eq!(atan2(-0.0, -1.0), -PI);
        assert_eq!(atan2(1.0, 0.0), FRAC_PI_2);
        assert_eq!(atan2(-1.0, 0.0), -FRAC_PI_2);
        assert_eq!(atan2(0.0, 0.0), 0.0);
        assert!(atan2(f32::NAN, 1.0).is_nan() && atan2(1.0, f32::NAN).is_nan());
    }
}
