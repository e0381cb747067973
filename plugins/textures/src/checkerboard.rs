//! `checkerboard`: two values in alternating squares, two by two over the
//! unit square (Mitsuba 3's `checkerboard`; pbrt-v4's `checkerboard`
//! without its filtering).

use lumis_api::{
    Params, PluginKind, PluginParams, PluginSpec, Result, Rgb, Texture, TextureQuery, UvTransform,
};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Texture,
    name: "checkerboard",
    source: lumis_api::source_file!(),
    doc: "two values in alternating squares, 2x2 over the unit uv square",
    params: CheckerboardParams::SPECS,
};

#[derive(Debug, Clone, Copy, PluginParams)]
pub struct CheckerboardParams {
    /// the value of the square at the uv origin, linear RGB
    #[param(default = 0.4)]
    pub color0: Rgb,
    /// the value of the other squares, linear RGB
    #[param(default = 0.2)]
    pub color1: Rgb,
    #[param(flatten)]
    pub transform: UvTransform,
}

#[derive(Debug, Clone, Copy)]
pub struct Checkerboard {
    pub colors: [Rgb; 2],
    pub transform: UvTransform,
}

impl Checkerboard {
    pub fn from_params(params: &Params) -> Result<Self> {
        let p = CheckerboardParams::read(params)?;
        Ok(Self {
            colors: [p.color0, p.color1],
            transform: p.transform,
        })
    }

    /// Which value covers `uv`: squares of side 1/2, alternating in both
    /// directions, so each value covers half of any whole square of uv.
    #[inline]
    fn square(uv: lumis_api::Vec2) -> usize {
        let cells = (uv * 2.0).floor();
        (cells.x + cells.y).rem_euclid(2.0) as usize
    }
}

impl Texture for Checkerboard {
    #[inline]
    fn eval(&self, query: &TextureQuery) -> Rgb {
        let uv = self.transform.apply(query).uv;
        if !uv.is_finite() {
            return self.colors[0];
        }
        self.colors[Self::square(uv).min(1)]
    }
}

#[cfg(test)]
mod tests {
    use lumis_api::Vec2;

    use super::*;

    fn board(transform: UvTransform) -> Checkerboard {
        Checkerboard {
            colors: [Rgb::splat(1.0), Rgb::splat(0.0)],
            transform,
        }
    }

    /// The mean over `[0, 1]^2` on an `n x n` grid of cell centres.
    fn grid_mean(t: &Checkerboard, n: usize) -> f64 {
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let uv = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                sum += t.eval(&TextureQuery::at(uv)).r as f64;
            }
        }
        sum / (n * n) as f64
    }

    #[test]
    fn each_value_covers_half_the_area() {
        assert_eq!(grid_mean(&board(UvTransform::default()), 64), 0.5);
        let scaled = UvTransform {
            uv_scale: Vec2::new(3.0, 5.0),
            ..UvTransform::default()
        };
        assert_eq!(grid_mean(&board(scaled), 60), 0.5);
        // Rotated by 45 degrees the squares cut the grid cells; the area
        // fraction is still one half, up to the grid's resolution.
        let rotated = UvTransform {
            uv_rotation: 45.0,
            uv_scale: Vec2::splat(4.0),
            ..UvTransform::default()
        };
        let mean = grid_mean(&board(rotated), 400);
        assert!((mean - 0.5).abs() < 0.01, "{mean}");
    }

    #[test]
    fn squares_alternate_and_start_at_the_origin() {
        let t = board(UvTransform::default());
        let at = |u, v| t.eval(&TextureQuery::at(Vec2::new(u, v))).r;
        assert_eq!(at(0.25, 0.25), 1.0);
        assert_eq!(at(0.75, 0.25), 0.0);
        assert_eq!(at(0.25, 0.75), 0.0);
        assert_eq!(at(0.75, 0.75), 1.0);
        // Negative coordinates continue the pattern.
        assert_eq!(at(-0.25, 0.25), 0.0);
        assert_eq!(at(-0.25, -0.25), 1.0);
        assert_eq!(at(f32::NAN, 0.0), 1.0);
    }
}
