//! A light written in Python.

use lumis_api::ray::SurfacePoint;
use lumis_api::{
    Error, Light, LightKind, LightSample, LightSampleContext, Result, Rgb, Vec2, Vec3,
};
use pyo3::prelude::*;

use super::object::PluginObject;
use super::values::{rgb, tuple, vec3};

/// A Python object with `kind`, `sample_li`, `pdf_li`, `l` and `power`
/// (and optionally `preprocess`), as a [`Light`]: points and directions
/// cross as `(x, y, z)` tuples in world space.
pub struct PythonLight {
    object: PluginObject,
    kind: LightKind,
}

impl PythonLight {
    pub fn new(object: PluginObject) -> Result<Self> {
        let kind = object.attribute("kind", |k| k.extract::<String>())?;
        let kind = match kind.as_str() {
            "delta_position" => LightKind::DeltaPosition,
            "infinite" => LightKind::Infinite,
            other => {
                return Err(Error::msg(format!(
                    "{}: kind \"{other}\": expected \"delta_position\" or \"infinite\" (a Python light is not attached to a shape)",
                    object.label
                )))
            }
        };
        Ok(Self { object, kind })
    }
}

impl Light for PythonLight {
    fn kind(&self) -> LightKind {
        self.kind
    }

    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        let args = (tuple(ctx.p()), tuple(ctx.ns), (u.x, u.y));
        self.object.call("sample_li", args, |answer| {
            if answer.is_none() {
                return Ok(None);
            }
            let (l, wi, pdf, p): (Bound<'_, PyAny>, Bound<'_, PyAny>, f32, Bound<'_, PyAny>) =
                answer.extract()?;
            Ok(Some(LightSample {
                l: rgb(&l)?,
                wi: vec3(&wi)?,
                pdf,
                p: SurfacePoint::isolated(vec3(&p)?),
            }))
        })
    }

    fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3) -> f32 {
        let args = (tuple(ctx.p()), tuple(ctx.ns), tuple(wi));
        self.object.call("pdf_li", args, |p| p.extract::<f32>())
    }

    fn l(&self, p: Vec3, n: Vec3, uv: Vec2, w: Vec3) -> Rgb {
        let args = (tuple(p), tuple(n), (uv.x, uv.y), tuple(w));
        self.object.call("l", args, rgb)
    }

    fn power(&self) -> Rgb {
        self.object.call("power", (), rgb)
    }

    fn preprocess(&mut self, scene_center: Vec3, scene_radius: f32) {
        let has = self.object.attribute("preprocess", |_| Ok(())).is_ok();
        if has {
            self.object.call(
                "preprocess",
                (tuple(scene_center), scene_radius),
                |_| Ok(()),
            );
        }
    }
}
