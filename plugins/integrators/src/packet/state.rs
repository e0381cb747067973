//! The state of a packet's paths, one lane per path, as structure of
//! arrays: what [`PathState`] holds for one path, each field a lane array.

use lumis_api::lanes::{Floats, LaneMask, RgbLanes, Vec3Lanes, LANES};
use lumis_api::{LightSampleContext, Ray, Rgb};

use crate::estimator::BsdfRay;
use crate::path_state::PathState;

/// [`PathState`] of each lane of a packet, and which camera ray each lane
/// is tracing.
pub struct PathLanes {
    pub radiance: RgbLanes,
    pub beta: RgbLanes,
    pub origin: Vec3Lanes,
    pub dir: Vec3Lanes,
    pub t_max: Floats,
    /// How each lane's ray was sampled ([`BsdfRay`]), field by field.
    pub prev: [LightSampleContext; LANES],
    pub pdf: Floats,
    pub specular: LaneMask,
    pub scale: Floats,
    pub eta_scale: Floats,
    pub segments: [u32; LANES],
    /// The camera ray (and sampler lane) of each lane's path.
    pub path: [usize; LANES],
    /// The lanes holding a path that goes on.
    pub live: LaneMask,
}

impl Default for PathLanes {
    fn default() -> Self {
        Self {
            radiance: RgbLanes::default(),
            beta: RgbLanes::default(),
            origin: Vec3Lanes::default(),
            dir: Vec3Lanes::default(),
            t_max: [0.0; LANES],
            prev: [LightSampleContext::at(lumis_api::Vec3::ZERO); LANES],
            pdf: [0.0; LANES],
            specular: LaneMask::NONE,
            scale: [0.0; LANES],
            eta_scale: [0.0; LANES],
            segments: [0; LANES],
            path: [0; LANES],
            live: LaneMask::NONE,
        }
    }
}

impl PathLanes {
    /// Lane `i` starts camera ray `path`.
    pub fn start(&mut self, i: usize, path: usize, camera_ray: &Ray) {
        self.set(i, &PathState::new(camera_ray));
        self.path[i] = path;
        self.live.set(i, true);
    }

    /// Lane `i`'s ray.
    #[inline]
    pub fn ray(&self, i: usize) -> Ray {
        Ray {
            o: self.origin.get(i),
            d: self.dir.get(i),
            t_max: self.t_max[i],
        }
    }

    /// Lane `i`'s path.
    #[inline]
    pub fn get(&self, i: usize) -> PathState {
        PathState {
            radiance: self.radiance.get(i),
            beta: self.beta.get(i),
            ray: self.ray(i),
            from: BsdfRay {
                prev: self.prev[i],
                pdf: self.pdf[i],
                specular: self.specular.contains(i),
                scale: self.scale[i],
            },
            eta_scale: self.eta_scale[i],
            segments: self.segments[i],
        }
    }

    /// Lane `i` holds `path`.
    #[inline]
    pub fn set(&mut self, i: usize, path: &PathState) {
        self.radiance.set(i, path.radiance);
        self.beta.set(i, path.beta);
        self.origin.set(i, path.ray.o);
        self.dir.set(i, path.ray.d);
        self.t_max[i] = path.ray.t_max;
        self.prev[i] = path.from.prev;
        self.pdf[i] = path.from.pdf;
        self.specular.set(i, path.from.specular);
        self.scale[i] = path.from.scale;
        self.eta_scale[i] = path.eta_scale;
        self.segments[i] = path.segments;
    }

    /// The radiance lane `i` has gathered.
    #[inline]
    pub fn radiance(&self, i: usize) -> Rgb {
        self.radiance.get(i)
    }
}
