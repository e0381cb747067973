//! `{{plugin}}`: constant emission from a quad shape, sampled uniformly by
//! area.
//!
//! A light answers for directions seen from a shading point, so the density
//! of a point drawn by area, `1 / A`, is converted to solid angle (pbrt-v4
//! section 4.2.3): `pdf_w = pdf_A d^2 / |cos theta_l|`, `d` the distance
//! to the point and `theta_l` the angle between the light's normal and the
//! direction back to the shading point. `pdf_li` must give the same density
//! for the direction a sample took: it finds the point by intersecting the
//! ray with the quad.
//!
//! A scene attaches it to a quad shape:
//! `emission = { type = "{{plugin}}", radiance = [4, 4, 4] }`.

use std::f32::consts::PI;

use lumis_api::math::gamma;
use lumis_api::ray::SurfacePoint;
use lumis_api::{
    Aabb, Error, Light, LightBounds, LightKind, LightSample, LightSampleContext, LightShape,
    Params, PluginKind, PluginParams, PluginSpec, Registrar, Result, Rgb, Vec2, Vec3,
};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Light,
    name: "{{plugin}}",
    source: lumis_api::source_file!(),
    doc: "one-sided emission of a quad shape, sampled uniformly by area (density converted to solid angle)",
    params: QuadEmitterParams::SPECS,
};

/// The keys of the shape's `emission = { ... }` table.
#[derive(Debug, Clone, Copy, PluginParams)]
pub struct QuadEmitterParams {
    /// emitted radiance in linear RGB, on the side the normal faces
    #[param(default = 1.0)]
    pub radiance: Rgb,
}

/// Registers the plugin; exported through [`lumis_api::lumis_plugin!`].
pub fn register(registry: &mut dyn Registrar) -> Result<()> {
    registry.add_light(SPEC, |params, shape| {
        Ok(Box::new(QuadEmitter::from_params(params, shape)?))
    })
}

lumis_api::lumis_plugin!(register);

/// The parallelogram `corner + s edge_u + t edge_v`, `s, t` in `[0, 1]`,
/// emitting `radiance` toward `edge_u x edge_v`.
#[derive(Debug, Clone)]
pub struct QuadEmitter {
    corner: Vec3,
    edge_u: Vec3,
    edge_v: Vec3,
    normal: Vec3,
    area: f32,
    radiance: Rgb,
}

impl QuadEmitter {
    pub fn new(corner: Vec3, edge_u: Vec3, edge_v: Vec3, radiance: Rgb) -> Result<Self> {
        let cross = edge_u.cross(edge_v);
        let area = cross.length();
        if !(area > 0.0 && area.is_finite()) {
            return Err(Error::msg(
                "the quad's edges are parallel or degenerate (zero area)",
            ));
        }
        Ok(Self {
            corner,
            edge_u,
            edge_v,
            normal: cross / area,
            area,
            radiance,
        })
    }

    /// Reads the parameters; the factory gets the shape the emission is
    /// attached to, and refuses any but a quad.
    pub fn from_params(params: &Params, shape: &LightShape) -> Result<Self> {
        let p = QuadEmitterParams::read(params)?;
        if !(p.radiance.min_component() >= 0.0 && p.radiance.is_finite()) {
            return Err(params.error(
                QuadEmitterParams::KEYS.radiance,
                format!("must be finite and non-negative, got {}", p.radiance),
            ));
        }
        match *shape {
            LightShape::Quad {
                corner,
                edge_u,
                edge_v,
            } => Self::new(corner, edge_u, edge_v, p.radiance),
            _ => Err(Error::msg(format!(
                "{}: this light is the emission of a quad: use [[shape]] type = \"quad\" with emission = {{ type = \"{}\", ... }}",
                params.owner(),
                SPEC.name
            ))),
        }
    }

    /// The distance along `o + t w` (unit `w`) at which the ray crosses
    /// the quad, if it does.
    fn intersect(&self, o: Vec3, w: Vec3) -> Option<f32> {
        let denom = self.normal.dot(w);
        if denom == 0.0 {
            return None;
        }
        let t = self.normal.dot(self.corner - o) / denom;
        if !(t > 0.0 && t.is_finite()) {
            return None;
        }
        // The hit's coordinates along the two (possibly skew) edges.
        let d = o + w * t - self.corner;
        let (uu, vv, uv) = (
            self.edge_u.length_squared(),
            self.edge_v.length_squared(),
            self.edge_u.dot(self.edge_v),
        );
        let (du, dv) = (d.dot(self.edge_u), d.dot(self.edge_v));
        let det = uu * vv - uv * uv;
        let s = (du * vv - dv * uv) / det;
        let r = (dv * uu - du * uv) / det;
        ((0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&r)).then_some(t)
    }

    /// Solid-angle density of a point at distance `distance` along `wi`:
    /// `d^2 / (|cos theta_l| A)`; zero seen from behind, where nothing is
    /// emitted and `sample_li` returns nothing.
    fn solid_angle_pdf(&self, distance: f32, wi: Vec3) -> f32 {
        let cos_light = self.normal.dot(-wi);
        if cos_light <= 0.0 {
            return 0.0;
        }
        let pdf = distance * distance / (cos_light * self.area);
        if pdf.is_finite() {
            pdf
        } else {
            0.0
        }
    }
}

impl Light for QuadEmitter {
    fn kind(&self) -> LightKind {
        LightKind::Area
    }

    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        let (su, sv) = (self.edge_u * u.x, self.edge_v * u.y);
        let point = SurfacePoint {
            p: self.corner + su + sv,
            // A bound on the rounding error of the two products and sums,
            // so that shadow rays neither start nor end inside the quad.
            p_error: gamma(6) * (self.corner.abs() + su.abs() + sv.abs()),
            n: self.normal,
        };
        let to_light = point.p - ctx.p();
        let distance = to_light.length();
        let wi = to_light / distance;
        let pdf = self.solid_angle_pdf(distance, wi);
        (pdf > 0.0).then_some(LightSample {
            l: self.radiance,
            wi,
            pdf,
            p: point,
        })
    }

    fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3) -> f32 {
        self.intersect(ctx.p(), wi)
            .map_or(0.0, |t| self.solid_angle_pdf(t, wi))
    }

    fn l(&self, _p: Vec3, n: Vec3, _uv: Vec2, w: Vec3) -> Rgb {
        if n.dot(w) > 0.0 {
            self.radiance
        } else {
            Rgb::BLACK
        }
    }

    /// `pi L A`: the radiant flux of a Lambertian emitter (one side).
    fn power(&self) -> Rgb {
        self.radiance * (PI * self.area)
    }

    /// Where the quad is and which way it emits, so that the `bvh` light
    /// sampler can weigh it by its place (without bounds a light is picked
    /// as an environment is, wherever the shading point).
    fn bounds(&self) -> Option<LightBounds> {
        let (c, u, v) = (self.corner, self.edge_u, self.edge_v);
        Some(LightBounds::planar(
            Aabb::of_points([c, c + u, c + v, c + u + v]),
            self.normal,
            self.power().luminance(),
            false,
        ))
    }
}
