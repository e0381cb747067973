//! An equirectangular (latitude-longitude) radiance map in the convention
//! of Mitsuba 3's `envmap`: in the map's frame `+y` is up, `v = theta / pi`
//! runs from the top row (`+y`) down, and `u = phi / (2 pi)` with
//! `d = (sin theta sin phi, cos theta, -sin theta cos phi)`, so the centre
//! of the image looks along `+z`.

use std::f32::consts::PI;

use lumis_api::{Rgb, Vec2, Vec3};
use lumis_sampling::special::{atan2, sin_cos_turns};

/// `floor(x)` as an integer, without the library call `f32::floor` makes
/// on baseline x86-64 (no `roundss`); NaN gives 0.
#[inline]
fn floor(x: f32) -> i64 {
    let t = x as i64;
    if t as f32 > x {
        t - 1
    } else {
        t
    }
}

/// The texels of a map, bilinearly interpolated between texel centres:
/// wrapped in `u`, clamped in `v`.
#[derive(Debug, Clone)]
pub struct Equirect {
    width: usize,
    height: usize,
    texels: Vec<Rgb>,
}

impl Equirect {
    /// Panics unless `texels` holds `width * height > 0` values (the
    /// factory checks the file first).
    pub fn new(width: usize, height: usize, texels: Vec<Rgb>) -> Self {
        assert!(width > 0 && height > 0 && texels.len() == width * height);
        Self {
            width,
            height,
            texels,
        }
    }

    pub fn width(&self) -> usize {
        self.width
    }

    /// Bytes its texels hold.
    pub fn byte_size(&self) -> usize {
        std::mem::size_of_val(self.texels.as_slice())
    }

    pub fn height(&self) -> usize {
        self.height
    }

    #[inline]
    fn texel(&self, x: usize, y: usize) -> Rgb {
        self.texels[y * self.width + x]
    }

    /// The map's coordinates of the direction `d` (map frame; any
    /// length), and its `sin theta` if `d` is unit. Both angles come from
    /// `atan2`, which keeps `theta` accurate at the poles where `acos`
    /// of `d.y` would not.
    #[inline]
    pub fn uv_of(d: Vec3) -> (Vec2, f32) {
        let sin_theta = (d.x * d.x + d.z * d.z).sqrt();
        let u = atan2(d.x, -d.z) * (0.5 / PI);
        let u = if u < 0.0 { u + 1.0 } else { u };
        let v = atan2(sin_theta, d.y) * (1.0 / PI);
        (Vec2::new(u.min(1.0), v), sin_theta)
    }

    /// The direction (map frame) at `uv`, and its `sin theta`.
    #[inline]
    pub fn direction_of(uv: Vec2) -> (Vec3, f32) {
        let (sin_theta, cos_theta) = sin_cos_turns(0.5 * uv.y);
        let (sin_phi, cos_phi) = sin_cos_turns(uv.x);
        let d = Vec3::new(sin_theta * sin_phi, cos_theta, -sin_theta * cos_phi);
        (d, sin_theta)
    }

    /// Bilinear interpolation of the texel centres around `uv`.
    #[inline]
    pub fn lookup(&self, uv: Vec2) -> Rgb {
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        let (x0, y0) = (floor(x), floor(y));
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let w = self.width as i64;
        // Inside the map but for the seam's neighbour: the division of
        // `rem_euclid` only off the common path.
        let wrap = |i: i64| if (0..w).contains(&i) { i } else { i.rem_euclid(w) } as usize;
        let clamp = |j: i64| j.clamp(0, self.height as i64 - 1) as usize;
        let (xa, xb) = (wrap(x0), wrap(x0 + 1));
        let (ya, yb) = (clamp(y0), clamp(y0 + 1));
        let top = self.texel(xa, ya) * (1.0 - fx) + self.texel(xb, ya) * fx;
        let bottom = self.texel(xa, yb) * (1.0 - fx) + self.texel(xb, yb) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// The average over each texel's cell of the bilinear interpolation
    /// of the luminance, times `sin theta` at the cell's centre: what
    /// importance sampling draws cells by, row-major.
    ///
    /// The interpolation in a cell reaches half way into its neighbours,
    /// so a cell next to a lit texel is lit too and must be drawn: its
    /// average is `1/8, 3/4, 1/8` of the texels before, at and after it
    /// along each axis (the integrals of the tent each texel spreads),
    /// with the same wrapping and clamping as [`Self::lookup`].
    ///
    /// `compensated` subtracts the average luminance over the sphere
    /// first (pbrt-v4's MIS compensation, Karlik et al. 2019): cells
    /// dimmer than the average get no light samples, and BSDF sampling,
    /// through MIS, carries them. A map with nothing above its average
    /// (a constant one) keeps its plain weights.
    pub fn sampling_weights(&self, compensated: bool) -> Vec<f32> {
        const TENT: [f64; 3] = [0.125, 0.75, 0.125];
        let (w, h) = (self.width as i64, self.height as i64);
        let lum: Vec<f64> = self.texels.iter().map(|t| t.luminance() as f64).collect();
        let at = |x: i64, y: i64| lum[(y.clamp(0, h - 1) * w + x.rem_euclid(w)) as usize];
        let sin_theta: Vec<f64> = (0..h)
            .map(|y| ((y as f64 + 0.5) / h as f64 * std::f64::consts::PI).sin())
            .collect();
        let mut cells = Vec::with_capacity(self.texels.len());
        for y in 0..h {
            for x in 0..w {
                let mut sum = 0.0;
                for (dy, ty) in TENT.iter().enumerate() {
                    for (dx, tx) in TENT.iter().enumerate() {
                        sum += ty * tx * at(x + dx as i64 - 1, y + dy as i64 - 1);
                    }
                }
                cells.push(sum);
            }
        }
        let row_of = |k: usize| k / self.width;
        if compensated {
            // The average over solid angle: rows weighted by sin theta.
            let total: f64 = cells
                .iter()
                .enumerate()
                .map(|(k, c)| c * sin_theta[row_of(k)])
                .sum();
            let average = total / (sin_theta.iter().sum::<f64>() * self.width as f64);
            let above: Vec<f64> = cells.iter().map(|c| (c - average).max(0.0)).collect();
            if above.iter().any(|&c| c > 0.0) {
                cells = above;
            }
        }
        cells
            .iter()
            .enumerate()
            .map(|(k, c)| (c * sin_theta[row_of(k)]) as f32)
            .collect()
    }

    /// `integral of L over the sphere`, each texel constant over its cell:
    /// the sum of texels times their cells' solid angles,
    /// `(2 pi / width) (cos theta_top - cos theta_bottom)`.
    pub fn radiance_integral(&self) -> Rgb {
        let mut sum = [0.0f64; 3];
        for y in 0..self.height {
            let theta = |row: usize| row as f64 / self.height as f64 * std::f64::consts::PI;
            let solid_angle = 2.0 * std::f64::consts::PI / self.width as f64
                * (theta(y).cos() - theta(y + 1).cos());
            for x in 0..self.width {
                let t = self.texel(x, y);
                sum[0] += t.r as f64 * solid_angle;
                sum[1] += t.g as f64 * solid_angle;
                sum[2] += t.b as f64 * solid_angle;
            }
        }
        Rgb::new(sum[0] as f32, sum[1] as f32, sum[2] as f32)
    }
}
