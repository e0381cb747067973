//! An image pyramid and its filtered lookups over a footprint in uv:
//! trilinear and EWA (pbrt-v4 `MIPMap`, section 10.4.3; EWA after Heckbert
//! 1989 and Greene and Heckbert 1986, as pbrt-v4 writes it).

use lumis_api::{Rgb, TextureQuery, Vec2};

use super::texels::{Texels, Wrap};

/// The most an EWA ellipse may be stretched: a longer ellipse is widened,
/// trading blur for a bounded number of texels (pbrt-v4's
/// `maxAnisotropy`, 8 by default).
const MAX_ANISOTROPY: f32 = 8.0;

/// Levels from the image down to one texel, each half the size of the one
/// above (rounded up), every texel the mean of the (up to) four it covers.
/// pbrt-v4 first resamples an image to power-of-two sizes; here an odd
/// size's last row or column is averaged with the wrapped neighbour
/// instead, so a level of odd size is not an exact box average.
pub fn pyramid(base: Texels, wrap: [Wrap; 2]) -> Vec<Texels> {
    let mut levels = vec![base];
    loop {
        let last = levels.last().expect("the base level");
        if last.width == 1 && last.height == 1 {
            return levels;
        }
        let (width, height) = (last.width.div_ceil(2), last.height.div_ceil(2));
        let values: Vec<Rgb> = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x as i64, y as i64)))
            .map(|(x, y)| {
                // A dimension of size one is not halved: its texel counts
                // twice rather than wrapping onto itself.
                let dx = if last.width > 1 { 1 } else { 0 };
                let dy = if last.height > 1 { 1 } else { 0 };
                0.25 * (last.texel(2 * x, 2 * y, wrap)
                    + last.texel(2 * x + dx, 2 * y, wrap)
                    + last.texel(2 * x, 2 * y + dy, wrap)
                    + last.texel(2 * x + dx, 2 * y + dy, wrap))
            })
            .collect();
        levels.push(Texels::linear(width, height, values));
    }
}

/// The level (fractional, 0 the finest) whose texels are `width` wide in uv.
fn level_of(levels: &[Texels], width: f32) -> f32 {
    (levels.len() - 1) as f32 + width.max(1e-8).log2()
}

/// Trilinear filtering (pbrt-v4 `MIPMap::Filter`, trilinear case): the
/// footprint's larger extent picks two adjacent levels, each looked up
/// bilinearly, and the lookups are blended. Without a footprint: bilinear
/// on the finest level.
pub fn trilinear(levels: &[Texels], query: &TextureQuery, uv: Vec2, wrap: [Wrap; 2]) -> Rgb {
    if !query.has_footprint() {
        return levels[0].bilinear(uv, wrap);
    }
    let (dx, dy) = query.derivatives();
    let width = 2.0 * dx.abs().max(dy.abs()).max_element();
    let level = level_of(levels, width);
    if level <= 0.0 {
        return levels[0].bilinear(uv, wrap);
    }
    let last = levels.len() - 1;
    if level >= last as f32 {
        return levels[last].texel(0, 0, wrap);
    }
    let i = level.floor() as usize;
    let t = level - i as f32;
    (1.0 - t) * levels[i].bilinear(uv, wrap) + t * levels[i + 1].bilinear(uv, wrap)
}

/// EWA filtering (pbrt-v4 `MIPMap::Filter`, EWA case): a Gaussian over the
/// ellipse whose axes are the footprint's derivatives, on the level where
/// the minor axis spans a few texels, blended with the next level.
pub fn ewa(levels: &[Texels], query: &TextureQuery, uv: Vec2, wrap: [Wrap; 2]) -> Rgb {
    let (mut major, mut minor) = query.derivatives();
    if major.length_squared() < minor.length_squared() {
        std::mem::swap(&mut major, &mut minor);
    }
    let longer = major.length();
    let mut shorter = minor.length();
    // Clamp the eccentricity by widening the minor axis.
    if shorter * MAX_ANISOTROPY < longer && shorter > 0.0 {
        let scale = longer / (shorter * MAX_ANISOTROPY);
        minor *= scale;
        shorter *= scale;
    }
    if shorter == 0.0 || !shorter.is_finite() {
        return levels[0].bilinear(uv, wrap);
    }
    let lod = level_of(levels, shorter).max(0.0);
    let i = lod.floor() as usize;
    let t = lod - i as f32;
    let fine = ewa_level(levels, i, uv, major, minor, wrap);
    if t == 0.0 {
        return fine;
    }
    (1.0 - t) * fine + t * ewa_level(levels, i + 1, uv, major, minor, wrap)
}

/// The Gaussian-weighted mean over the ellipse on one level (pbrt-v4
/// `MIPMap::EWA`): the implicit ellipse `A s^2 + B s t + C t^2 < 1` of the
/// axes in texel units, each texel inside weighted by `e^(-2 r^2) - e^(-2)`.
fn ewa_level(
    levels: &[Texels],
    level: usize,
    uv: Vec2,
    major: Vec2,
    minor: Vec2,
    wrap: [Wrap; 2],
) -> Rgb {
    let Some(texels) = levels.get(level) else {
        return levels[levels.len() - 1].texel(0, 0, wrap);
    };
    let size = Vec2::new(texels.width as f32, texels.height as f32);
    let (s, t) = (uv.x * size.x - 0.5, uv.y * size.y - 0.5);
    let (d0, d1) = (major * size, minor * size);
    // The ellipse's implicit coefficients, plus one texel of blur so that
    // it always covers a texel centre.
    let mut a = d0.y * d0.y + d1.y * d1.y + 1.0;
    let mut b = -2.0 * (d0.x * d0.y + d1.x * d1.y);
    let mut c = d0.x * d0.x + d1.x * d1.x + 1.0;
    let inv_f = 1.0 / (a * c - b * b * 0.25);
    a *= inv_f;
    b *= inv_f;
    c *= inv_f;
    // Its bounding box.
    let det = -b * b + 4.0 * a * c;
    let inv_det = 1.0 / det;
    let (u_sqrt, v_sqrt) = ((det * c).sqrt(), (a * det).sqrt());
    let s0 = (s - 2.0 * inv_det * u_sqrt).ceil() as i64;
    let s1 = (s + 2.0 * inv_det * u_sqrt).floor() as i64;
    let t0 = (t - 2.0 * inv_det * v_sqrt).ceil() as i64;
    let t1 = (t + 2.0 * inv_det * v_sqrt).floor() as i64;
    let falloff = (-2.0f32).exp();
    let (mut sum, mut weights) = (Rgb::BLACK, 0.0);
    for it in t0..=t1 {
        let tt = it as f32 - t;
        for is in s0..=s1 {
            let ss = is as f32 - s;
            let r2 = a * ss * ss + b * ss * tt + c * tt * tt;
            if r2 < 1.0 {
                let w = (-2.0 * r2).exp() - falloff;
                sum += texels.texel(is, it, wrap) * w;
                weights += w;
            }
        }
    }
    if weights > 0.0 {
        sum / weights
    } else {
        texels.bilinear(uv, wrap)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Rgb, b: Rgb, tol: f32) -> bool {
        (a - b).max_component() <= tol && (b - a).max_component() <= tol
    }

    /// A 16 x 8 image of stripes: texel (x, y) is x % 2 (0 or 1 in red).
    fn stripes() -> Texels {
        Texels::linear(
            16,
            8,
            (0..8)
                .flat_map(|_| (0..16).map(|x| Rgb::new((x % 2) as f32, 0.5, 1.0)))
                .collect(),
        )
    }

    const REPEAT: [Wrap; 2] = [Wrap::Repeat; 2];

    fn footprint(uv: Vec2, dx: Vec2, dy: Vec2) -> TextureQuery {
        TextureQuery::new(uv, dx, dy)
    }

    #[test]
    fn the_pyramid_halves_down_to_one_texel_and_keeps_the_mean() {
        let levels = pyramid(stripes(), REPEAT);
        let sizes: Vec<(usize, usize)> = levels.iter().map(|l| (l.width, l.height)).collect();
        assert_eq!(sizes, [(16, 8), (8, 4), (4, 2), (2, 1), (1, 1)]);
        // Level 0 is the image itself.
        assert_eq!(levels[0], stripes());
        // Stripes of one texel average to their mean from level 1 on.
        for level in &levels[1..] {
            for v in level.iter() {
                assert_eq!(v, Rgb::new(0.5, 0.5, 1.0));
            }
        }
    }

    #[test]
    fn no_footprint_or_a_tiny_one_is_bilinear_on_level_zero() {
        let levels = pyramid(stripes(), REPEAT);
        let uv = Vec2::new(0.3, 0.4);
        let bilinear = levels[0].bilinear(uv, REPEAT);
        assert_eq!(
            trilinear(&levels, &TextureQuery::at(uv), uv, REPEAT),
            bilinear
        );
        assert_eq!(ewa(&levels, &TextureQuery::at(uv), uv, REPEAT), bilinear);
        let tiny = footprint(uv, Vec2::new(1e-4, 0.0), Vec2::new(0.0, 1e-4));
        assert_eq!(trilinear(&levels, &tiny, uv, REPEAT), bilinear);
    }

    #[test]
    fn a_footprint_over_many_stripes_averages_them() {
        let levels = pyramid(stripes(), REPEAT);
        // Four texels wide: both filters see the stripes' mean, 0.5.
        let q = footprint(
            Vec2::new(0.5, 0.5),
            Vec2::new(4.0 / 16.0, 0.0),
            Vec2::new(0.0, 4.0 / 8.0),
        );
        for got in [
            trilinear(&levels, &q, q.uv, REPEAT),
            ewa(&levels, &q, q.uv, REPEAT),
        ] {
            assert!(close(got, Rgb::new(0.5, 0.5, 1.0), 0.02), "{got:?}");
        }
        // A footprint wider than the image reads the coarsest level.
        let huge = footprint(q.uv, Vec2::new(10.0, 0.0), Vec2::new(0.0, 10.0));
        assert_eq!(
            trilinear(&levels, &huge, q.uv, REPEAT),
            Rgb::new(0.5, 0.5, 1.0)
        );
    }

    #[test]
    fn a_constant_image_reads_its_value_through_every_filter() {
        let c = Rgb::new(0.2, 0.4, 0.8);
        let base = Texels::linear(13, 7, vec![c; 13 * 7]);
        for wrap in [
            [Wrap::Repeat; 2],
            [Wrap::Mirror; 2],
            [Wrap::Clamp, Wrap::Repeat],
        ] {
            let levels = pyramid(base.clone(), wrap);
            for i in 0..100 {
                let uv = Vec2::new(i as f32 * 0.173 - 3.0, i as f32 * -0.291 + 2.0);
                let scale = 10f32.powf(i as f32 / 25.0 - 3.5);
                let q = footprint(
                    uv,
                    Vec2::new(scale, 0.3 * scale),
                    Vec2::new(-0.2 * scale, 0.05 * scale),
                );
                for got in [trilinear(&levels, &q, uv, wrap), ewa(&levels, &q, uv, wrap)] {
                    assert!(close(got, c, 1e-5), "{uv} {scale}: {got:?}");
                }
            }
        }
    }
}
