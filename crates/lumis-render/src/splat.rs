//! Light that an integrator adds to the film away from its camera ray's
//! pixel ([`lumis_core::Integrator::li_splat`]), summed in fixed point.
//!
//! Any tile's paths may land on any pixel, so the worker threads add to
//! one image at once. Each splat is rounded to a multiple of
//! [`SPLAT_QUANTUM`] and the sums are whole numbers: they are the same
//! whatever order the threads add in, so a render's splats do not depend
//! on the thread count, a render resumed from a checkpoint continues them
//! bit for bit, and parts add up exactly. The rounding, at most half a
//! quantum (3e-8) per splat, is far below the noise of any render.

use std::sync::atomic::{AtomicI64, AtomicU64, Ordering};

use lumis_core::{Error, Result, Rgb, UVec2, Vec2};

/// The fixed-point unit of the splat sums: 2^-24.
pub const SPLAT_QUANTUM: f64 = 1.0 / (1u64 << 24) as f64;

/// The largest splat component kept, 2^38: the sums of 2^25 such splats
/// still fit an `i64`. A larger one (or a NaN) is dropped and counted.
const LARGEST_SPLAT: f64 = (1u64 << 38) as f64;

/// `v` in units of [`SPLAT_QUANTUM`], rounded to nearest; `None` for a
/// value out of range.
fn to_fixed(v: f32) -> Option<i64> {
    let v = v as f64;
    (v.abs() <= LARGEST_SPLAT).then(|| (v / SPLAT_QUANTUM).round() as i64)
}

/// `a + b` for two splat sums, or the error of a sum beyond an `i64`.
pub fn add_sums(a: i64, b: i64) -> Result<i64> {
    a.checked_add(b).ok_or_else(|| {
        Error::msg("the film's splat sums overflow (beyond 5e11 per pixel): render fewer samples")
    })
}

/// The splats of one run of samples over the whole image, added by every
/// worker thread.
pub struct SplatBuffer {
    width: u32,
    height: u32,
    sums: Vec<[AtomicI64; 3]>,
    /// Splats dropped for a component that is not finite or too large.
    dropped: AtomicU64,
}

impl SplatBuffer {
    pub fn new(resolution: UVec2) -> Self {
        let count = resolution.x as usize * resolution.y as usize;
        Self {
            width: resolution.x,
            height: resolution.y,
            sums: (0..count).map(|_| Default::default()).collect(),
            dropped: AtomicU64::new(0),
        }
    }

    /// Adds `l` to the pixel holding film position `raster` (box filter:
    /// the pixel it falls in); a position off the film adds nothing.
    pub fn add(&self, raster: Vec2, l: Rgb) {
        let (x, y) = (raster.x.floor(), raster.y.floor());
        if !(x >= 0.0 && y >= 0.0 && x < self.width as f32 && y < self.height as f32) {
            return;
        }
        let (Some(r), Some(g), Some(b)) = (to_fixed(l.r), to_fixed(l.g), to_fixed(l.b)) else {
            self.dropped.fetch_add(1, Ordering::Relaxed);
            return;
        };
        let pixel = &self.sums[y as usize * self.width as usize + x as usize];
        for (sum, v) in pixel.iter().zip([r, g, b]) {
            if v != 0 {
                sum.fetch_add(v, Ordering::Relaxed);
            }
        }
    }

    /// How many splats were dropped.
    pub fn dropped(&self) -> u64 {
        self.dropped.load(Ordering::Relaxed)
    }

    /// Adds the run's sums to `sums`, the film's.
    pub fn add_to(&self, sums: &mut [[i64; 3]]) -> Result<()> {
        for (to, from) in sums.iter_mut().zip(&self.sums) {
            for c in 0..3 {
                to[c] = add_sums(to[c], from[c].load(Ordering::Relaxed))?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splats_land_in_their_pixel_and_sum_in_any_order() {
        let buffer = SplatBuffer::new(UVec2::new(3, 2));
        let splats = [
            (Vec2::new(2.5, 1.99), Rgb::new(0.1, 1e-9, 3.0)),
            (Vec2::new(2.0, 1.0), Rgb::new(1e6, 0.0, 0.25)),
            (Vec2::new(-0.1, 0.0), Rgb::splat(1.0)),
            (Vec2::new(0.0, 2.0), Rgb::splat(1.0)),
            (Vec2::new(0.0, 0.0), Rgb::new(f32::NAN, 0.0, 0.0)),
            (Vec2::new(0.0, 0.0), Rgb::new(1e12, 0.0, 0.0)),
        ];
        for (raster, l) in splats {
            buffer.add(raster, l);
        }
        let mut sums = vec![[0i64; 3]; 6];
        buffer.add_to(&mut sums).unwrap();
        let expected = |v: f64| (v / SPLAT_QUANTUM).round() as i64;
        assert_eq!(
            sums[5],
            [
                expected(0.1f32 as f64) + expected(1e6),
                0,
                expected(3.0) + expected(0.25)
            ]
        );
        assert!(sums[..5].iter().all(|s| *s == [0; 3]));
        assert_eq!(buffer.dropped(), 2);
    }
}
