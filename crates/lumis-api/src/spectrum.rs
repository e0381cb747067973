//! Linear RGB radiance and reflectance.

use std::ops::{Add, AddAssign, Div, DivAssign, Index, Mul, MulAssign, Sub};

/// A linear RGB triple: radiance, throughput or reflectance.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Rgb {
    pub r: f32,
    pub g: f32,
    pub b: f32,
}

impl Rgb {
    pub const BLACK: Rgb = Rgb::splat(0.0);
    pub const WHITE: Rgb = Rgb::splat(1.0);

    #[inline]
    pub const fn new(r: f32, g: f32, b: f32) -> Self {
        Self { r, g, b }
    }

    #[inline]
    pub const fn splat(v: f32) -> Self {
        Self { r: v, g: v, b: v }
    }

    #[inline]
    pub fn is_black(&self) -> bool {
        self.r == 0.0 && self.g == 0.0 && self.b == 0.0
    }

    #[inline]
    pub fn is_finite(&self) -> bool {
        self.r.is_finite() && self.g.is_finite() && self.b.is_finite()
    }

    #[inline]
    pub fn max_component(&self) -> f32 {
        self.r.max(self.g).max(self.b)
    }

    /// Scaled down, where its largest component exceeds `max`, to have
    /// `max` there (pbrt-v4 `RGBFilm::AddSample`, `maxcomponentvalue`): the
    /// hue stays, and the rare paths whose radiance is huge (caustics
    /// through a small light, found by a BSDF sample) stop showing as
    /// fireflies. Biased: the energy above the cap is lost. A value whose
    /// components are all within the cap is returned as it was, bit for bit.
    #[inline]
    pub fn clamp_max_component(self, max: f32) -> Rgb {
        let m = self.max_component();
        if m > max {
            self * (max / m)
        } else {
            self
        }
    }

    #[inline]
    pub fn min_component(&self) -> f32 {
        self.r.min(self.g).min(self.b)
    }

    #[inline]
    pub fn average(&self) -> f32 {
        (self.r + self.g + self.b) / 3.0
    }

    /// Relative luminance of linear sRGB (Rec. 709 primaries).
    #[inline]
    pub fn luminance(&self) -> f32 {
        0.212_671 * self.r + 0.715_160 * self.g + 0.072_169 * self.b
    }

    #[inline]
    pub fn to_array(self) -> [f32; 3] {
        [self.r, self.g, self.b]
    }

    #[inline]
    pub fn map(self, f: impl Fn(f32) -> f32) -> Self {
        Self::new(f(self.r), f(self.g), f(self.b))
    }
}

/// As a scene writes a colour: `[0.5, 0.25, inf]`.
impl std::fmt::Display for Rgb {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "[{}, {}, {}]", self.r, self.g, self.b)
    }
}

impl From<[f32; 3]> for Rgb {
    fn from(v: [f32; 3]) -> Self {
        Self::new(v[0], v[1], v[2])
    }
}

impl Index<usize> for Rgb {
    type Output = f32;
    fn index(&self, i: usize) -> &f32 {
        match i {
            0 => &self.r,
            1 => &self.g,
            2 => &self.b,
            _ => panic!("Rgb index {i} out of range"),
        }
    }
}

macro_rules! componentwise {
    ($trait:ident, $fn:ident, $op:tt, $assign_trait:ident, $assign_fn:ident) => {
        impl $trait for Rgb {
            type Output = Rgb;
            #[inline]
            fn $fn(self, o: Rgb) -> Rgb {
                Rgb::new(self.r $op o.r, self.g $op o.g, self.b $op o.b)
            }
        }
        impl $trait<f32> for Rgb {
            type Output = Rgb;
            #[inline]
            fn $fn(self, s: f32) -> Rgb {
                Rgb::new(self.r $op s, self.g $op s, self.b $op s)
            }
        }
        impl $assign_trait for Rgb {
            #[inline]
            fn $assign_fn(&mut self, o: Rgb) {
                *self = *self $op o;
            }
        }
        impl $assign_trait<f32> for Rgb {
            #[inline]
            fn $assign_fn(&mut self, s: f32) {
                *self = *self $op s;
            }
        }
    };
}

componentwise!(Add, add, +, AddAssign, add_assign);
componentwise!(Mul, mul, *, MulAssign, mul_assign);
componentwise!(Div, div, /, DivAssign, div_assign);

impl Sub for Rgb {
    type Output = Rgb;
    #[inline]
    fn sub(self, o: Rgb) -> Rgb {
        Rgb::new(self.r - o.r, self.g - o.g, self.b - o.b)
    }
}

impl Mul<Rgb> for f32 {
    type Output = Rgb;
    #[inline]
    fn mul(self, c: Rgb) -> Rgb {
        c * self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_colour_displays_as_a_scene_writes_it() {
        assert_eq!(
            Rgb::new(0.5, f32::INFINITY, 0.0).to_string(),
            "[0.5, inf, 0]"
        );
    }
}
