//! A grid of linear texels and its lookups: wrapped texel access, nearest
//! and bilinear reconstruction (pbrt-v4 `Image::Bilerp`).

use lumis_api::{ParamChoice, Rgb, Vec2};

/// How coordinates outside the image map back into it (pbrt-v4
/// `WrapMode`, Mitsuba 3's `wrap_mode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum Wrap {
    /// The image tiles the plane.
    Repeat,
    /// The image tiles the plane, every other copy mirrored, so edges meet.
    Mirror,
    /// The edge texels extend outwards.
    Clamp,
}

impl Wrap {
    /// The texel index that `i` refers to in a row (or column) of `n`.
    #[inline(always)]
    pub fn index(self, i: i64, n: usize) -> usize {
        // Every mode leaves an index inside the row where it is: most
        // lookups, and no division for them.
        if (0..n as i64).contains(&i) {
            i as usize
        } else {
            self.index_outside(i, n)
        }
    }

    /// [`Self::index`] of an `i` outside `0..n`.
    fn index_outside(self, i: i64, n: usize) -> usize {
        let n = n as i64;
        (match self {
            // A power-of-two width (most textures) needs no division.
            Wrap::Repeat if n.count_ones() == 1 => i & (n - 1),
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Mirror => {
                let m = i.rem_euclid(2 * n);
                if m >= n {
                    2 * n - 1 - m
                } else {
                    m
                }
            }
            Wrap::Clamp => i.clamp(0, n - 1),
        }) as usize
    }
}

/// Texels, row by row from the top (texture coordinate `(0, 0)` is the
/// top-left corner of the image, as in glTF), read as linear RGB.
#[derive(Debug, Clone, PartialEq)]
pub struct Texels {
    pub width: usize,
    pub height: usize,
    values: TexelValues,
}

/// How texels are held.
#[derive(Debug, Clone, PartialEq)]
enum TexelValues {
    Linear(Vec<Rgb>),
    /// The bytes of an 8-bit image, 3 bytes a texel instead of 12, and
    /// the linear value of each byte (pbrt-v4 keeps 8-bit images so too):
    /// a 4096 x 4096 texture takes 48 MiB instead of 192.
    Bytes {
        texels: Vec<[u8; 3]>,
        decode: Box<[f32; 256]>,
    },
}

impl Texels {
    /// Linear texels.
    pub fn linear(width: usize, height: usize, values: Vec<Rgb>) -> Self {
        debug_assert_eq!(values.len(), width * height);
        Self {
            width,
            height,
            values: TexelValues::Linear(values),
        }
    }

    /// 8-bit texels whose byte `b` stands for the linear value `decode(b)`.
    pub fn bytes(
        width: usize,
        height: usize,
        texels: Vec<[u8; 3]>,
        decode: impl Fn(u8) -> f32,
    ) -> Self {
        debug_assert_eq!(texels.len(), width * height);
        Self {
            width,
            height,
            values: TexelValues::Bytes {
                texels,
                decode: Box::new(std::array::from_fn(|b| decode(b as u8))),
            },
        }
    }

    /// The texel at integer coordinates `(x, y)`, wrapped in u and in v.
    #[inline]
    pub fn texel(&self, x: i64, y: i64, wrap: [Wrap; 2]) -> Rgb {
        self.at(wrap[0].index(x, self.width), wrap[1].index(y, self.height))
    }

    /// The texel at column `x` and row `y`, both inside the image.
    #[inline]
    fn at(&self, x: usize, y: usize) -> Rgb {
        let i = y * self.width + x;
        match &self.values {
            TexelValues::Linear(values) => values[i],
            TexelValues::Bytes { texels, decode } => {
                let [r, g, b] = texels[i];
                Rgb::new(decode[r as usize], decode[g as usize], decode[b as usize])
            }
        }
    }

    /// Every texel, row by row.
    pub fn iter(&self) -> impl Iterator<Item = Rgb> + '_ {
        (0..self.height as i64).flat_map(move |y| {
            (0..self.width as i64).map(move |x| self.texel(x, y, [Wrap::Clamp; 2]))
        })
    }

    /// Bytes the texels take.
    pub fn byte_size(&self) -> usize {
        match &self.values {
            TexelValues::Linear(values) => values.capacity() * std::mem::size_of::<Rgb>(),
            TexelValues::Bytes { texels, decode } => {
                texels.capacity() * std::mem::size_of::<[u8; 3]>()
                    + std::mem::size_of_val(&**decode)
            }
        }
    }

    /// The texel that covers `uv`.
    #[inline]
    pub fn nearest(&self, uv: Vec2, wrap: [Wrap; 2]) -> Rgb {
        let x = (uv.x * self.width as f32).floor() as i64;
        let y = (uv.y * self.height as f32).floor() as i64;
        self.texel(x, y, wrap)
    }

    /// Bilinear interpolation between the four texel centres around `uv`
    /// (texel `(x, y)` has its centre at `((x + 1/2) / w, (y + 1/2) / h)`).
    #[inline]
    pub fn bilinear(&self, uv: Vec2, wrap: [Wrap; 2]) -> Rgb {
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        // Two columns and two rows, each wrapped once for the four texels.
        let [x0, x1] = [x0, x0 + 1].map(|x| wrap[0].index(x, self.width));
        let [y0, y1] = [y0, y0 + 1].map(|y| wrap[1].index(y, self.height));
        (1.0 - fy) * ((1.0 - fx) * self.at(x0, y0) + fx * self.at(x1, y0))
            + fy * ((1.0 - fx) * self.at(x0, y1) + fx * self.at(x1, y1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Rgb, b: Rgb) -> bool {
        (a - b).max_component() < 1e-6 && (b - a).max_component() < 1e-6
    }

    /// A 3 x 2 image whose texel (x, y) has red x and green y.
    fn ramp() -> Texels {
        Texels::linear(
            3,
            2,
            (0..2)
                .flat_map(|y| (0..3).map(move |x| Rgb::new(x as f32, y as f32, 1.0)))
                .collect(),
        )
    }

    #[test]
    fn wrap_modes_at_the_edges() {
        let n = 3;
        let indices = |w: Wrap| (-4..7).map(|i| w.index(i, n)).collect::<Vec<_>>();
        assert_eq!(indices(Wrap::Repeat), [2, 0, 1, 2, 0, 1, 2, 0, 1, 2, 0]);
        assert_eq!(indices(Wrap::Mirror), [2, 2, 1, 0, 0, 1, 2, 2, 1, 0, 0]);
        assert_eq!(indices(Wrap::Clamp), [0, 0, 0, 0, 0, 1, 2, 2, 2, 2, 2]);
    }

    #[test]
    fn every_wrap_agrees_with_its_definition_on_any_width() {
        // Power-of-two widths take a shortcut for repeat; every width takes
        // one for indices inside the row.
        for n in [1, 2, 3, 4, 5, 8, 64, 100] {
            let m = n as i64;
            for i in -3 * m - 2..3 * m + 2 {
                assert_eq!(Wrap::Repeat.index(i, n), i.rem_euclid(m) as usize);
                let mirrored = i.rem_euclid(2 * m);
                let mirrored = if mirrored >= m {
                    2 * m - 1 - mirrored
                } else {
                    mirrored
                };
                assert_eq!(Wrap::Mirror.index(i, n), mirrored as usize);
                assert_eq!(Wrap::Clamp.index(i, n), i.clamp(0, m - 1) as usize);
            }
        }
    }

    #[test]
    fn bilinear_reproduces_texels_at_their_centres() {
        let t = ramp();
        for wrap in [Wrap::Repeat, Wrap::Mirror, Wrap::Clamp] {
            for y in 0..2 {
                for x in 0..3 {
                    let uv = Vec2::new((x as f32 + 0.5) / 3.0, (y as f32 + 0.5) / 2.0);
                    let got = t.bilinear(uv, [wrap; 2]);
                    let want = t.texel(x as i64, y as i64, [Wrap::Clamp; 2]);
                    assert!(close(got, want), "{wrap:?} {x} {y}: {got:?}");
                    assert_eq!(t.nearest(uv, [wrap; 2]), want);
                }
            }
        }
    }

    #[test]
    fn bilinear_interpolates_and_wraps_between_edges() {
        let t = ramp();
        // Half way between texels 0 and 1 of the top row.
        let mid = t.bilinear(Vec2::new(1.0 / 3.0, 0.25), [Wrap::Clamp; 2]);
        assert!((mid.r - 0.5).abs() < 1e-6 && mid.g == 0.0, "{mid:?}");
        // At u = 0 the left neighbour is texel 2 (repeat), texel 0 (mirror,
        // clamp): half way between the last and first column's values.
        let u0 = Vec2::new(0.0, 0.25);
        assert!((t.bilinear(u0, [Wrap::Repeat; 2]).r - 1.0).abs() < 1e-6);
        assert!((t.bilinear(u0, [Wrap::Mirror; 2]).r - 0.0).abs() < 1e-6);
        assert!((t.bilinear(u0, [Wrap::Clamp; 2]).r - 0.0).abs() < 1e-6);
    }

    #[test]
    fn wrap_modes_apply_per_axis() {
        // 2 x 2: red, green / blue, white.
        let t = Texels::linear(
            2,
            2,
            vec![
                Rgb::new(1.0, 0.0, 0.0),
                Rgb::new(0.0, 1.0, 0.0),
                Rgb::new(0.0, 0.0, 1.0),
                Rgb::WHITE,
            ],
        );
        let wrap = [Wrap::Clamp, Wrap::Mirror];
        // Clamped in u: far right is the right column; mirrored in v: v in
        // (1, 1.5) reflects to the bottom row, (1.5, 2) to the top.
        assert_eq!(
            t.nearest(Vec2::new(7.0, 0.2), wrap),
            Rgb::new(0.0, 1.0, 0.0)
        );
        assert_eq!(
            t.nearest(Vec2::new(-3.0, 1.2), wrap),
            Rgb::new(0.0, 0.0, 1.0)
        );
        assert_eq!(
            t.nearest(Vec2::new(0.2, 1.7), wrap),
            Rgb::new(1.0, 0.0, 0.0)
        );
        // Nearest: no blend halfway between red and green.
        assert_eq!(
            t.nearest(Vec2::new(0.49, 0.25), wrap),
            Rgb::new(1.0, 0.0, 0.0)
        );
        assert_eq!(
            t.nearest(Vec2::new(0.51, 0.25), wrap),
            Rgb::new(0.0, 1.0, 0.0)
        );
    }

    #[test]
    fn a_constant_image_reads_its_value_everywhere() {
        let c = Rgb::new(0.2, 0.4, 0.8);
        let t = Texels::linear(5, 3, vec![c; 15]);
        for i in 0..200 {
            let uv = Vec2::new(i as f32 * 0.173 - 7.0, i as f32 * -0.291 + 3.0);
            for wrap in [Wrap::Repeat, Wrap::Mirror, Wrap::Clamp] {
                let got = t.bilinear(uv, [wrap; 2]);
                assert!(close(got, c), "{uv}: {got:?}");
            }
        }
    }
}
