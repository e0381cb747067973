//! The film: per-pixel sums of radiance samples in double precision, the
//! number of samples every pixel has taken, and the sums behind the
//! outputs a scene asks for beside the colour ([`Aov`]).
//!
//! The sums, not the means, are the render's state: a render continued from
//! them adds each later sample to the same running sum, in the same order,
//! as an uninterrupted render would, so its image is bit for bit the same.
//! Every output's buffer is a sum of the same kind, so the same holds for
//! them; a buffer exists only when an output needs it.

use lumis_core::{Error, Result, Rgb, UVec2};
use lumis_image::Image;

use crate::adaptive::{pixel_error, still_active, AdaptiveSampling};
use crate::aov::Aov;
use crate::first_hit::FirstHit;
use crate::splat::{add_sums, SPLAT_QUANTUM};

/// The sums of what a pixel's camera rays saw first ([`FirstHit`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FirstHitSums {
    pub albedo: [f64; 3],
    pub normal: [f64; 3],
    pub depth: f64,
}

/// What adaptive sampling keeps per pixel.
#[derive(Debug, Clone, PartialEq)]
pub struct AdaptiveState {
    pub settings: AdaptiveSampling,
    /// Samples each pixel has taken: indices `0..counts[i]`.
    pub counts: Vec<u32>,
    /// The sum of each pixel's odd-index samples: one of two independent
    /// half-buffers (the other is the sum of the rest).
    pub odd_sums: Vec<[f64; 3]>,
    /// Pixels still sampling; a pixel that stopped never starts again.
    pub active: Vec<bool>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Film {
    pub width: usize,
    pub height: usize,
    /// Row-major from the top-left pixel: the sum of each pixel's finite
    /// samples (a NaN or infinite one counts as a sample of zero).
    pub sums: Vec<[f64; 3]>,
    /// The sum of the squares of the same samples, for the variance output.
    /// Sums (not Welford's running mean) because they are added in the
    /// same order whatever the passes, so a resumed render's are the same
    /// bits; in double precision, `Σx² − (Σx)²/n` keeps far more digits
    /// than the `f32` output needs at any sample count a render reaches.
    pub squares: Option<Vec<[f64; 3]>>,
    /// The first-hit sums, for the albedo, normal and depth outputs.
    pub first_hits: Option<Vec<FirstHitSums>>,
    /// The outputs asked for, each once, in [`Aov::ALL`]'s order.
    pub aovs: Vec<Aov>,
    /// With adaptive sampling, the per-pixel counts and half-buffers.
    pub adaptive: Option<AdaptiveState>,
    /// With an integrator that splats, the sums of the light it added to
    /// each pixel from other pixels' samples, in units of
    /// [`SPLAT_QUANTUM`] (`splat.rs`); the image adds them over the
    /// samples per pixel.
    pub splats: Option<Vec<[i64; 3]>>,
    /// The first sample index the sums hold: 0 for a whole render, `A` for
    /// the slice `A..B` of a render split into parts.
    pub start: u32,
    /// Sample indices `start..samples` of the sampler have been rendered:
    /// every pixel has taken them all, or (adaptive sampling) stopped
    /// before.
    pub samples: u32,
}

/// `count` copies of `value`, or an error saying how much memory they
/// needed where that cannot be allocated.
fn try_buffer<T: Clone>(count: usize, value: T, too_large: impl Fn() -> Error) -> Result<Vec<T>> {
    let mut buffer = Vec::new();
    buffer.try_reserve_exact(count).map_err(|_| too_large())?;
    buffer.resize(count, value);
    Ok(buffer)
}

/// The bytes per pixel of a film's sums: the colour's, the squares' for
/// the variance output, and the first hits' for the albedo, normal and
/// depth outputs.
fn sums_bytes_per_pixel(aovs: &[Aov]) -> usize {
    let wants_squares = aovs.contains(&Aov::Variance);
    let wants_first_hits = aovs.iter().any(|a| a.needs_first_hit());
    std::mem::size_of::<[f64; 3]>() * (1 + wants_squares as usize)
        + std::mem::size_of::<FirstHitSums>() * wants_first_hits as usize
}

/// The bytes per pixel of adaptive sampling's state: a count, a
/// half-buffer and a flag.
const ADAPTIVE_BYTES_PER_PIXEL: usize =
    std::mem::size_of::<u32>() + std::mem::size_of::<[f64; 3]>() + std::mem::size_of::<bool>();

/// The bytes per pixel of the splats: the film's sums and those of the run
/// being rendered ([`crate::SplatBuffer`]).
const SPLAT_BYTES_PER_PIXEL: usize = 2 * std::mem::size_of::<[i64; 3]>();

impl Film {
    /// The bytes a film of `resolution` with `aovs` (and adaptive
    /// sampling's state, if `adaptive`, and the splats' sums, if
    /// `splats`) holds: what [`Film::try_with_aovs`],
    /// [`Film::with_adaptive`] and a render that splats allocate, known
    /// before they do.
    pub fn memory_bytes(resolution: UVec2, aovs: &[Aov], adaptive: bool, splats: bool) -> u64 {
        let per_pixel = sums_bytes_per_pixel(aovs)
            + ADAPTIVE_BYTES_PER_PIXEL * adaptive as usize
            + SPLAT_BYTES_PER_PIXEL * splats as usize;
        (u64::from(resolution.x) * u64::from(resolution.y)).saturating_mul(per_pixel as u64)
    }

    /// An empty film, or an error saying how much memory it needed where
    /// that cannot be allocated.
    pub fn try_new(resolution: UVec2) -> Result<Self> {
        Self::try_with_aovs(resolution, &[])
    }

    /// An empty film with the buffers `aovs` need.
    pub fn try_with_aovs(resolution: UVec2, aovs: &[Aov]) -> Result<Self> {
        let (width, height) = (resolution.x as usize, resolution.y as usize);
        let wants_squares = aovs.contains(&Aov::Variance);
        let wants_first_hits = aovs.iter().any(|a| a.needs_first_hit());
        let bytes_per_pixel = sums_bytes_per_pixel(aovs);
        let too_large = || {
            Error::msg(format!(
                "film resolution {width}x{height}: a {width}x{height} image needs {:.1} GB of memory, which cannot be allocated",
                width as f64 * height as f64 * bytes_per_pixel as f64 * 1e-9
            ))
        };
        let count = width.checked_mul(height).ok_or_else(too_large)?;
        Ok(Self {
            width,
            height,
            sums: try_buffer(count, [0.0; 3], too_large)?,
            squares: match wants_squares {
                true => Some(try_buffer(count, [0.0; 3], too_large)?),
                false => None,
            },
            first_hits: match wants_first_hits {
                true => Some(try_buffer(count, FirstHitSums::default(), too_large)?),
                false => None,
            },
            aovs: {
                let mut aovs = aovs.to_vec();
                aovs.sort();
                aovs.dedup();
                aovs
            },
            adaptive: None,
            splats: None,
            start: 0,
            samples: 0,
        })
    }

    /// The splats' sums, made (all zero) on first use: a film keeps them
    /// once an integrator that splats has rendered to it.
    pub fn splat_sums(&mut self) -> Result<&mut [[i64; 3]]> {
        if self.splats.is_none() {
            let too_large = || Error::msg("film: no memory for the splats' sums");
            self.splats = Some(try_buffer(self.sums.len(), [0; 3], too_large)?);
        }
        Ok(self.splats.as_deref_mut().unwrap_or_default())
    }

    /// This film, sampling adaptively as `settings` say.
    pub fn with_adaptive(mut self, settings: AdaptiveSampling) -> Result<Self> {
        let count = self.sums.len();
        let too_large = || Error::msg("film: no memory for adaptive sampling's buffers");
        self.adaptive = Some(AdaptiveState {
            settings,
            counts: try_buffer(count, 0, too_large)?,
            odd_sums: try_buffer(count, [0.0; 3], too_large)?,
            active: try_buffer(count, true, too_large)?,
        });
        Ok(self)
    }

    /// Whether pixel `i` takes the next samples.
    #[inline]
    pub fn is_active(&self, i: usize) -> bool {
        self.adaptive.as_ref().is_none_or(|a| a.active[i])
    }

    /// This empty film as the slice of sample indices starting at `start`
    /// (a part of a render split over processes): its sums will hold
    /// samples `start..` only, which [`Film::append`] adds to the slices
    /// before them.
    pub fn starting_at(mut self, start: u32) -> Self {
        self.start = start;
        self.samples = start;
        self
    }

    /// The samples pixel `i` has taken.
    #[inline]
    pub fn samples_of(&self, i: usize) -> u32 {
        self.adaptive
            .as_ref()
            .map_or(self.samples - self.start, |a| a.counts[i])
    }

    /// Adds `slice`, the sums of the sample indices that follow this
    /// film's, to this film's sums: a render split into slices (parts
    /// rendered in other processes) is put together by appending them in
    /// index order, each sum once, so the result does not depend on where
    /// or in which order the parts ran. Adaptive sampling cannot be split
    /// (which pixels still sample depends on all their earlier samples).
    pub fn append(&mut self, slice: &Film) -> Result<()> {
        if self.adaptive.is_some() || slice.adaptive.is_some() {
            return Err(Error::msg(
                "an adaptively sampled film cannot be split into slices",
            ));
        }
        if slice.start != self.samples {
            return Err(Error::msg(format!(
                "the slice holds samples {}..{}, not the ones from {} on",
                slice.start, slice.samples, self.samples
            )));
        }
        if slice.splats.is_none() && self.splats.is_some() {
            return Err(Error::msg(
                "the slice has no splats where the film has: its integrator differs",
            ));
        }
        if (slice.width, slice.height) != (self.width, self.height) || slice.aovs != self.aovs {
            return Err(Error::msg(format!(
                "the slice is a {}x{} film with outputs {:?}, not {}x{} with {:?}",
                slice.width, slice.height, slice.aovs, self.width, self.height, self.aovs
            )));
        }
        fn add<const N: usize>(to: &mut [[f64; N]], from: &[[f64; N]]) {
            for (to, from) in to.iter_mut().zip(from) {
                for c in 0..N {
                    to[c] += from[c];
                }
            }
        }
        add(&mut self.sums, &slice.sums);
        if let (Some(to), Some(from)) = (&mut self.squares, &slice.squares) {
            add(to, from);
        }
        if let (Some(to), Some(from)) = (&mut self.first_hits, &slice.first_hits) {
            for (to, from) in to.iter_mut().zip(from) {
                add(
                    std::slice::from_mut(&mut to.albedo),
                    std::slice::from_ref(&from.albedo),
                );
                add(
                    std::slice::from_mut(&mut to.normal),
                    std::slice::from_ref(&from.normal),
                );
                to.depth += from.depth;
            }
        }
        if let Some(from) = &slice.splats {
            for (to, from) in self.splat_sums()?.iter_mut().zip(from) {
                for c in 0..3 {
                    to[c] = add_sums(to[c], from[c])?;
                }
            }
        }
        self.samples = slice.samples;
        Ok(())
    }

    /// After `samples` sample indices: stops the pixels adaptive sampling
    /// finds converged, where `samples` is one of its checks.
    pub fn check_convergence(&mut self) {
        let (width, height, samples) = (self.width, self.height, self.samples);
        let Some(adaptive) = &mut self.adaptive else {
            return;
        };
        if !adaptive.settings.is_check(samples) {
            return;
        }
        let threshold = adaptive.settings.threshold as f64;
        let sums = &self.sums;
        let next = {
            let a = &*adaptive;
            still_active(width, height, &a.active, |i| {
                pixel_error(sums[i], a.odd_sums[i], a.counts[i]) < threshold
            })
        };
        adaptive.active = next;
    }

    /// Counts sample `index` of pixel `i`, whether finite or not (a NaN
    /// or infinite sample counts as a sample of zero).
    #[inline]
    pub fn count_sample(&mut self, i: usize) {
        if let Some(adaptive) = &mut self.adaptive {
            adaptive.counts[i] += 1;
        }
    }

    /// Adds finite radiance sample `index` to pixel `i`.
    #[inline]
    pub fn add_sample(&mut self, i: usize, index: u32, l: Rgb) {
        let l = [l.r as f64, l.g as f64, l.b as f64];
        let sum = &mut self.sums[i];
        for c in 0..3 {
            sum[c] += l[c];
        }
        if let Some(adaptive) = &mut self.adaptive {
            if index % 2 == 1 {
                let odd = &mut adaptive.odd_sums[i];
                for c in 0..3 {
                    odd[c] += l[c];
                }
            }
        }
        if let Some(squares) = &mut self.squares {
            let square = &mut squares[i];
            for c in 0..3 {
                square[c] += l[c] * l[c];
            }
        }
    }

    /// Adds what a camera ray of pixel `i` saw first.
    pub fn add_first_hit(&mut self, i: usize, hit: &FirstHit) {
        if let Some(first_hits) = &mut self.first_hits {
            let sums = &mut first_hits[i];
            for c in 0..3 {
                sums.albedo[c] += hit.albedo[c] as f64;
                sums.normal[c] += hit.normal[c] as f64;
            }
            sums.depth += hit.depth as f64;
        }
    }

    /// The pixels `min..max` (exclusive) as a film of their own, which
    /// [`Film::paste`] puts back.
    pub fn crop(&self, min: UVec2, max: UVec2) -> Film {
        let rows = || (min.y as usize..max.y as usize).map(|y| y * self.width);
        let (x0, x1) = (min.x as usize, max.x as usize);
        let crop = |buffer: &[[f64; 3]]| -> Vec<[f64; 3]> {
            rows()
                .flat_map(|row| buffer[row + x0..row + x1].iter().copied())
                .collect()
        };
        Film {
            width: x1 - x0,
            height: (max.y - min.y) as usize,
            sums: crop(&self.sums),
            squares: self.squares.as_deref().map(crop),
            first_hits: self.first_hits.as_ref().map(|buffer| {
                rows()
                    .flat_map(|row| buffer[row + x0..row + x1].iter().copied())
                    .collect()
            }),
            aovs: self.aovs.clone(),
            adaptive: self.adaptive.as_ref().map(|a| AdaptiveState {
                settings: a.settings,
                counts: rows()
                    .flat_map(|row| a.counts[row + x0..row + x1].iter().copied())
                    .collect(),
                odd_sums: crop(&a.odd_sums),
                active: rows()
                    .flat_map(|row| a.active[row + x0..row + x1].iter().copied())
                    .collect(),
            }),
            // The splats stay with the whole film: a tile's paths land
            // anywhere.
            splats: None,
            start: self.start,
            samples: self.samples,
        }
    }

    /// Writes `tile`, a [`Film::crop`] of this film at `min`, back.
    pub fn paste(&mut self, min: UVec2, tile: Film) {
        fn paste_rows<T: Copy>(to: &mut [T], width: usize, min: UVec2, tile: &[T], tw: usize) {
            for (r, row) in tile.chunks_exact(tw).enumerate() {
                let start = (min.y as usize + r) * width + min.x as usize;
                to[start..start + tw].copy_from_slice(row);
            }
        }
        let (width, tw) = (self.width, tile.width);
        paste_rows(&mut self.sums, width, min, &tile.sums, tw);
        if let (Some(to), Some(from)) = (&mut self.squares, &tile.squares) {
            paste_rows(to, width, min, from, tw);
        }
        if let (Some(to), Some(from)) = (&mut self.first_hits, &tile.first_hits) {
            paste_rows(to, width, min, from, tw);
        }
        if let (Some(to), Some(from)) = (&mut self.adaptive, &tile.adaptive) {
            paste_rows(&mut to.counts, width, min, &from.counts, tw);
            paste_rows(&mut to.odd_sums, width, min, &from.odd_sums, tw);
        }
    }

    /// `1 / n` for pixel `i`'s sample count `n`; 0 before any sample.
    fn inverse_samples(&self, i: usize) -> f64 {
        match self.samples_of(i) {
            0 => 0.0,
            n => 1.0 / n as f64,
        }
    }

    fn image_of(&self, pixel: impl Fn(usize) -> [f64; 3]) -> Image {
        Image {
            width: self.width,
            height: self.height,
            pixels: (0..self.width * self.height)
                .map(|i| pixel(i).map(|v| v as f32))
                .collect(),
        }
    }

    /// The image: each pixel's mean, black before any sample, plus its
    /// splats over the samples per pixel.
    pub fn image(&self) -> Image {
        let mean = |i: usize| self.sums[i].map(|s| s * self.inverse_samples(i));
        let Some(splats) = &self.splats else {
            return self.image_of(mean);
        };
        let splat_scale = match self.samples - self.start {
            0 => 0.0,
            n => SPLAT_QUANTUM / n as f64,
        };
        self.image_of(|i| {
            let mean = mean(i);
            std::array::from_fn(|c| mean[c] + splats[i][c] as f64 * splat_scale)
        })
    }

    /// The image of one output, or `None` for one this film was not made
    /// with. Single-channel outputs (depth, spp) fill every component.
    pub fn aov_image(&self, aov: Aov) -> Option<Image> {
        if !self.aovs.contains(&aov) {
            return None;
        }
        let inv = |i| self.inverse_samples(i);
        Some(match aov {
            Aov::Albedo => {
                let hits = self.first_hits.as_ref()?;
                self.image_of(|i| hits[i].albedo.map(|s| s * inv(i)))
            }
            Aov::Normal => {
                let hits = self.first_hits.as_ref()?;
                self.image_of(|i| hits[i].normal.map(|s| s * inv(i)))
            }
            Aov::Depth => {
                let hits = self.first_hits.as_ref()?;
                self.image_of(|i| [hits[i].depth * inv(i); 3])
            }
            Aov::Variance => {
                let squares = self.squares.as_ref()?;
                // The unbiased sample variance s² = (Σx² − (Σx)²/n)/(n − 1),
                // over n for the variance of the mean; 0 below two samples.
                let of_mean = |sum: f64, square: f64, n: u32| {
                    let n = n as f64;
                    if n < 2.0 {
                        0.0
                    } else {
                        ((square - sum * sum / n) / ((n - 1.0) * n)).max(0.0)
                    }
                };
                self.image_of(|i| {
                    let n = self.samples_of(i);
                    std::array::from_fn(|c| of_mean(self.sums[i][c], squares[i][c], n))
                })
            }
            Aov::Spp => self.image_of(|i| [self.samples_of(i) as f64; 3]),
        })
    }

    /// Every output the film was made with, named, in [`Aov::ALL`]'s order:
    /// what the EXR holds as layers beside the colour, and what a denoiser
    /// reads (`albedo`, `normal`).
    pub fn aov_images(&self) -> Vec<(Aov, Image)> {
        self.aovs
            .iter()
            .filter_map(|&aov| Some((aov, self.aov_image(aov)?)))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_image_is_the_mean_and_black_before_any_sample() {
        let mut film = Film::try_new(UVec2::new(2, 1)).unwrap();
        assert_eq!(film.image().pixels, vec![[0.0; 3]; 2]);
        film.sums[1] = [3.0, 6.0, 0.0];
        film.samples = 3;
        assert_eq!(film.image().pixels[1], [1.0, 2.0, 0.0]);
        let err = Film::try_new(UVec2::new(u32::MAX, u32::MAX)).unwrap_err();
        assert!(err.to_string().contains("GB of memory"), "{err}");
    }

    #[test]
    fn the_memory_estimate_is_what_a_film_allocates() {
        let resolution = UVec2::new(7, 3);
        for aovs in [&[][..], &[Aov::Variance], &[Aov::Albedo, Aov::Spp]] {
            for adaptive in [false, true] {
                let mut film = Film::try_with_aovs(resolution, aovs).unwrap();
                if adaptive {
                    film = film
                        .with_adaptive(AdaptiveSampling {
                            min_spp: 4,
                            max_spp: 16,
                            threshold: 0.1,
                        })
                        .unwrap();
                }
                let held = film.sums.len() * 24
                    + film.squares.as_ref().map_or(0, |s| s.len() * 24)
                    + film
                        .first_hits
                        .as_ref()
                        .map_or(0, |f| f.len() * std::mem::size_of::<FirstHitSums>())
                    + film.adaptive.as_ref().map_or(0, |a| {
                        a.counts.len() * 4 + a.odd_sums.len() * 24 + a.active.len()
                    });
                assert_eq!(
                    Film::memory_bytes(resolution, aovs, adaptive, false),
                    held as u64
                );
            }
        }
    }

    #[test]
    fn outputs_exist_only_when_asked_for() {
        let film = Film::try_new(UVec2::new(2, 2)).unwrap();
        assert!(film.squares.is_none() && film.first_hits.is_none());
        assert!(film.aov_images().is_empty());
        let film = Film::try_with_aovs(UVec2::new(2, 2), &[Aov::Spp, Aov::Depth]).unwrap();
        assert!(film.squares.is_none() && film.first_hits.is_some());
        let names: Vec<Aov> = film.aov_images().into_iter().map(|(a, _)| a).collect();
        assert_eq!(names, [Aov::Depth, Aov::Spp]);
        assert_eq!(film.aov_image(Aov::Variance), None);
    }

    #[test]
    fn variance_is_that_of_the_mean() {
        let mut film = Film::try_with_aovs(UVec2::new(1, 1), &[Aov::Variance]).unwrap();
        for x in [1.0, 2.0, 3.0, 6.0] {
            film.add_sample(0, 0, Rgb::new(x, 2.0 * x, 5.0));
        }
        film.samples = 4;
        // Sample variance of {1, 2, 3, 6}: 14/3; of the mean: 14/12.
        let v = film.aov_image(Aov::Variance).unwrap().pixels[0];
        assert!((v[0] - 14.0 / 12.0).abs() < 1e-6, "{v:?}");
        assert!((v[1] - 4.0 * 14.0 / 12.0).abs() < 1e-5, "{v:?}");
        assert_eq!(v[2], 0.0);
    }

    #[test]
    fn appended_slices_hold_each_sum_once_in_index_order() {
        let aovs = [Aov::Variance, Aov::Depth];
        let empty = || Film::try_with_aovs(UVec2::new(2, 1), &aovs).unwrap();
        let hit = |depth| FirstHit {
            albedo: lumis_core::Vec3::ONE,
            normal: lumis_core::Vec3::Z,
            depth,
        };
        // Sample k of pixel i has radiance 1/(k + 3 i + 1): sums that round.
        let value = |i: usize, k: u32| 1.0 / (k as f32 + 3.0 * i as f32 + 1.0);
        let slice = |range: std::ops::Range<u32>| {
            let mut film = empty().starting_at(range.start);
            for k in range.clone() {
                for i in 0..2 {
                    film.add_sample(i, k, Rgb::new(value(i, k), 1.0, 0.0));
                    film.add_first_hit(i, &hit(k as f32));
                }
            }
            film.samples = range.end;
            film
        };
        let (first, second) = (slice(0..3), slice(3..7));
        assert_eq!(second.samples_of(0), 4);
        assert_eq!(second.image().pixels[0][1], 1.0);
        let mut whole = empty();
        whole.append(&first).unwrap();
        whole.append(&second).unwrap();
        assert_eq!(whole.samples, 7);
        for i in 0..2 {
            let sum = |range: std::ops::Range<u32>| range.map(|k| value(i, k) as f64).sum::<f64>();
            assert_eq!(whole.sums[i][0], sum(0..3) + sum(3..7));
            assert_eq!(whole.sums[i][1], 7.0);
            assert_eq!(whole.first_hits.as_ref().unwrap()[i].depth, 21.0);
        }
        let err = whole.append(&first).unwrap_err().to_string();
        assert!(
            err.contains("samples 0..3, not the ones from 7 on"),
            "{err}"
        );
        let mut other = Film::try_new(UVec2::new(2, 1)).unwrap();
        let err = other.append(&first).unwrap_err().to_string();
        assert!(err.contains("outputs"), "{err}");
    }

    #[test]
    fn crop_and_paste_round_trip() {
        let aovs = [Aov::Variance, Aov::Albedo];
        let adaptive = AdaptiveSampling::new(2, 4, 0.1).unwrap();
        let mut film = Film::try_with_aovs(UVec2::new(5, 4), &aovs)
            .unwrap()
            .with_adaptive(adaptive)
            .unwrap();
        let mut tile = film.crop(UVec2::new(1, 2), UVec2::new(4, 4));
        assert_eq!((tile.width, tile.height), (3, 2));
        for i in 0..6 {
            tile.add_sample(i, 1, Rgb::new(i as f32, 0.0, 1.0));
            tile.count_sample(i);
            tile.add_first_hit(
                i,
                &FirstHit {
                    albedo: lumis_core::Vec3::splat(i as f32),
                    normal: lumis_core::Vec3::Z,
                    depth: 2.0,
                },
            );
        }
        let expected = tile.clone();
        film.paste(UVec2::new(1, 2), tile);
        assert_eq!(film.crop(UVec2::new(1, 2), UVec2::new(4, 4)), expected);
        assert_eq!(film.sums[2 * 5 + 2], [1.0, 0.0, 1.0]);
        assert_eq!(film.sums[5 + 2], [0.0; 3]);
    }
}
