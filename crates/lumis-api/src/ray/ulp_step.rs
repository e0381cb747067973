//! One ulp step of three coordinates at once: the hot end of
//! [`super::offset_ray_origin`], which every path vertex runs for its
//! continuation and shadow rays. Kept apart from the offset's statement:
//! this is how it runs fast (SSE2 on x86-64), not what it computes.

use glam::Vec3;

/// Every component of `po` moved one ulp toward the sign of the matching
/// component of `offset` by [`step_bits`], or `None` when a component of
/// `po` is zero, infinite or NaN (their step is not an integer increment).
/// On x86-64 the three lanes go through SSE2 at once (a path vertex offsets
/// three ray ends), with `safe_arch`'s safe wrappers of the intrinsics.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(super) fn step_away_fast(po: Vec3, offset: Vec3) -> Option<Vec3> {
    use glam::Vec3A;
    use safe_arch::*;
    let bits = cast_to_m128i_from_m128(m128(Vec3A::from(po).into()));
    let magnitude = bitand_m128i(bits, set_splat_i32_m128i(0x7fff_ffff));
    let finite_non_zero = bitand_m128i(
        cmp_gt_mask_i32_m128i(magnitude, zeroed_m128i()),
        cmp_lt_mask_i32_m128i(magnitude, set_splat_i32_m128i(0x7f80_0000)),
    );
    if move_mask_m128(cast_to_m128_from_m128i(finite_non_zero)) & 0b111 != 0b111 {
        return None;
    }
    let direction = m128(Vec3A::from(offset).into());
    // step_bits, lane-wise: +1 away from zero, -1 toward it, 0 for a zero
    // direction.
    let toward_zero =
        shr_imm_u32_m128i::<31>(bitxor_m128i(bits, cast_to_m128i_from_m128(direction)));
    let step = sub_i32_m128i(set_splat_i32_m128i(1), shl_imm_u32_m128i::<1>(toward_zero));
    let no_direction = cast_to_m128i_from_m128(cmp_eq_mask_m128(direction, zeroed_m128()));
    let stepped = add_i32_m128i(bits, bitandnot_m128i(no_direction, step));
    Some(Vec3A::from(cast_to_m128_from_m128i(stepped).0).into())
}

#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
pub(super) fn step_away_fast(po: Vec3, offset: Vec3) -> Option<Vec3> {
    let bits = po.to_array().map(f32::to_bits);
    if bits
        .iter()
        .any(|&b| (b & 0x7fff_ffff).wrapping_sub(1) >= 0x7f7f_ffff)
    {
        return None;
    }
    let [x, y, z] = [
        (bits[0], offset.x),
        (bits[1], offset.y),
        (bits[2], offset.z),
    ]
    .map(|(b, o)| f32::from_bits(step_bits(b, o)));
    Some(Vec3::new(x, y, z))
}

/// The bits of a finite, non-zero `v` moved one ulp toward the sign of
/// `direction` (unchanged for a zero direction): moving away from zero
/// increments the bits, toward zero decrements them.
#[cfg(any(test, not(target_arch = "x86_64")))]
#[inline(always)]
pub(super) fn step_bits(bits: u32, direction: f32) -> u32 {
    let toward_zero = (bits ^ direction.to_bits()) >> 31;
    let step = 1u32.wrapping_sub(toward_zero << 1);
    bits.wrapping_add(if direction == 0.0 { 0 } else { step })
}
