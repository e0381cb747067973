//! `measured`: an isotropic BRDF tabulated in the MERL format, rendered
//! from the table or from its tensor approximation, with a choice of
//! importance sampling.
//!
//! The table (Matusik et al. 2003) runs over Rusinkiewicz's half/difference
//! angles `(theta_h, theta_d, phi_d)` and is looked up trilinearly.
//! `sampling = "factored"` is the factored representation of Lawrence,
//! Rusinkiewicz and Ramamoorthi 2004. One-sided: black from behind. With
//! `bsdf` in place of `file`, an analytic BSDF is the source: the samplers
//! and the tensor are fitted to it directly, at their own nodes.
//! [Measured BRDFs](studies/measured.md) has the format, the
//! representations and what each sampling strategy buys.

use std::path::PathBuf;
use std::sync::Arc;

use lumis_api::params::NestedBsdf;
use lumis_api::{
    Bsdf, BsdfContext, BsdfFlags, BsdfSample, ParamChoice, Params, PluginKind, PluginParams,
    PluginSpec, Result, Rgb, Vec2, Vec3,
};
use lumis_sampling::warp;

use crate::compress::prepare_tensor;
use crate::grid::{Grid, Parameterization};
use crate::merl::MerlTable;
use crate::precompute::{prepare, Plan, PrecomputeReport, Prepared};
use crate::reflectance::Reflectance;
use crate::tabulate::check_representable;
use crate::tensor::node_grid;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Bsdf,
    name: "measured",
    source: lumis_api::source_file!(),
    doc: "isotropic BRDF tabulated in the MERL format, or an analytic BSDF fitted directly (f itself, or a rank-R tensor approximation of it); cosine, factored (Lawrence et al. 2004), tabulated or tensor (from the factors of a non-negative tensor, after Bilgili et al. 2011) sampling; one-sided",
    params: MeasuredParams::SPECS,
};

#[derive(Debug, Clone, PluginParams)]
pub struct MeasuredParams {
    /// MERL .binary table, relative to the scene file (make one with `lumis
    /// brdf tabulate`); or give bsdf instead
    pub file: Option<PathBuf>,
    /// instead of a table: the name of an isotropic, reflecting lumis BSDF
    /// declared before this one, which the samplers and the tensor are
    /// fitted to at their own nodes, and which representation = "table"
    /// renders as it is (a known ground truth for comparing
    /// parameterizations); evaluated with a default context, so textures do
    /// not vary over the surface; never cached
    pub bsdf: Option<NestedBsdf>,
    /// cosine (the baseline), factored (L separable terms in half-vector
    /// coordinates), tabulated (a 2D table per outgoing elevation, the
    /// memory-hungry reference), tensor (L non-negative terms fitted to f cos
    /// theta_i at the tensor's 90 x 90 x 180 nodes, sampled from their 1D
    /// factors)
    #[param(default = Factored)]
    pub sampling: MeasuredSampling,
    /// L, the terms of the factorization (factored, tensor)
    #[param(default = 2, range = (1, 16))]
    pub terms: i64,
    /// [outgoing elevations, half-angle bins, azimuth bins] of the
    /// precomputation (factored, tabulated; tensor sampling has its nodes)
    #[param(default = [32, 64, 64])]
    pub grid: Vec<i64>,
    /// the coordinates of wi about wo the precomputation tabulates
    /// (factored, tabulated) and the tensors are fitted over: half-diff (the
    /// half vector), pdv (the projected deviation vector, the tangent-plane
    /// part of wi + wo) or in-out (wi itself)
    #[param(default = HalfDiff)]
    pub parameterization: Parameterization,
    /// what f is rendered from: table (the source itself: the MERL table,
    /// trilinear, or the analytic bsdf) or tensor (rank terms of products
    /// of 1D factors per channel, fitted to ln(1 + f); the sampling is
    /// built from it)
    #[param(default = Table)]
    pub representation: MeasuredRepresentation,
    /// R, the rank-1 terms per colour channel of the tensor (tensor only)
    #[param(default = 8, range = (1, 32))]
    pub rank: i64,
    /// keep the precomputation next to the table
    /// (TABLE.STRATEGY-....lumis-cache), reused while the table is unchanged
    #[param(default = true)]
    pub cache: bool,
}

/// The `sampling` choice of `measured`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum MeasuredSampling {
    Cosine,
    Factored,
    Tabulated,
    Tensor,
}

/// The `representation` choice of `measured`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum MeasuredRepresentation {
    Table,
    Tensor,
}

/// Midpoints per cell and axis of the precomputation grid.
const SUPERSAMPLES: usize = 4;
/// The largest grid accepted: 64 MB of f32 for the tabulated strategy.
const MAX_GRID_CELLS: i64 = 1 << 24;

fn checked_grid(grid: &[i64], parameterization: Parameterization, params: &Params) -> Result<Grid> {
    match grid {
        &[n_o, n_w, n_phi]
            if [n_o, n_w, n_phi].iter().all(|n| (2..=1024).contains(n))
                && n_o * n_w * n_phi <= MAX_GRID_CELLS =>
        {
            Ok(Grid {
                n_o: n_o as usize,
                n_w: n_w as usize,
                n_phi: n_phi as usize,
                supersamples: SUPERSAMPLES,
                parameterization,
            })
        }
        _ => Err(params.error(
            MeasuredParams::KEYS.grid,
            format!("expected three integers in [2, 1024] with a product of at most {MAX_GRID_CELLS}, got {grid:?}"),
        )),
    }
}

#[derive(Debug, Clone)]
enum Strategy {
    Cosine,
    Prepared(Prepared),
}

#[derive(Debug, Clone)]
pub struct Measured {
    reflectance: Reflectance,
    strategy: Strategy,
}

impl Measured {
    pub fn cosine(reflectance: Reflectance) -> Self {
        Self {
            reflectance,
            strategy: Strategy::Cosine,
        }
    }

    pub fn with_sampler(reflectance: Reflectance, prepared: Prepared) -> Self {
        Self {
            reflectance,
            strategy: Strategy::Prepared(prepared),
        }
    }

    /// The BSDF and how its precomputations went: the tensor fit and the
    /// sampler's (also printed to stderr by [`Self::from_params`]).
    pub fn from_params_with_report(params: &Params) -> Result<(Self, Vec<String>)> {
        // Settings first: a typo is reported before a 35 MB read.
        let p = MeasuredParams::read(params)?;
        let keys = MeasuredParams::KEYS;
        // A setting the strategy does not use is refused if given.
        let tensor = p.representation == MeasuredRepresentation::Tensor;
        if !tensor {
            params.unread(keys.rank);
        }
        let plan = match p.sampling {
            MeasuredSampling::Cosine => {
                params.unread(keys.terms);
                params.unread(keys.grid);
                if !tensor {
                    params.unread(keys.cache);
                    params.unread(keys.parameterization);
                }
                None
            }
            MeasuredSampling::Factored => Some(Plan::Factored {
                terms: p.terms as usize,
            }),
            MeasuredSampling::Tabulated => {
                params.unread(keys.terms);
                Some(Plan::Tabulated)
            }
            MeasuredSampling::Tensor => {
                params.unread(keys.grid);
                Some(Plan::Tensor {
                    terms: p.terms as usize,
                })
            }
        };
        let setup = match plan {
            Some(plan) => {
                let grid = match plan {
                    Plan::Tensor { .. } => node_grid(p.parameterization),
                    Plan::Factored { .. } | Plan::Tabulated => {
                        checked_grid(&p.grid, p.parameterization, params)?
                    }
                };
                Some((plan, grid, p.cache))
            }
            None => None,
        };
        let source = match (&p.file, p.bsdf) {
            (Some(file), None) => Reflectance::Table(Arc::new(
                MerlTable::read(file).map_err(|e| params.error(keys.file, e))?,
            )),
            (None, Some(bsdf)) => {
                check_representable(bsdf.0.as_ref(), "the bsdf")
                    .map_err(|e| params.error(keys.bsdf, e))?;
                params.unread(keys.cache);
                Reflectance::Analytic(bsdf)
            }
            (Some(_), Some(_)) => {
                return Err(params.error(keys.bsdf, "give a table file or a bsdf, not both"))
            }
            (None, None) => {
                return Err(params.error(
                    keys.file,
                    "missing: give a MERL table file (or an analytic bsdf)",
                ))
            }
        };
        let file = p.file.as_deref();
        let mut messages = Vec::new();
        let reflectance = if tensor {
            let (tensor, report) =
                prepare_tensor(&source, file, p.parameterization, p.rank as usize, p.cache)?;
            messages.push(report.message);
            // The source is not needed any more: renders use the factors.
            Reflectance::Tensor(Arc::new(tensor))
        } else {
            source
        };
        let Some((plan, grid, use_cache)) = setup else {
            return Ok((Self::cosine(reflectance), messages));
        };
        let (prepared, report): (Prepared, PrecomputeReport) =
            prepare(&reflectance, file, plan, grid, use_cache)?;
        messages.push(report.message);
        Ok((Self::with_sampler(reflectance, prepared), messages))
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let (bsdf, messages) = Self::from_params_with_report(params)?;
        for message in messages {
            eprintln!("{message}");
        }
        Ok(bsdf)
    }

    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::BLACK;
        }
        self.reflectance.eval(wi, wo)
    }

    #[inline]
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        match &self.strategy {
            Strategy::Cosine => warp::cosine_hemisphere_pdf(wi.z),
            Strategy::Prepared(Prepared::Factored(f)) => f.pdf(wo, wi),
            Strategy::Prepared(Prepared::Tabulated(t)) => t.pdf(wo, wi),
            Strategy::Prepared(Prepared::Tensor(t)) => t.pdf(wo, wi),
        }
    }
}

impl Bsdf for Measured {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::GLOSSY | BsdfFlags::REFLECTION
    }

    #[inline]
    fn f(&self, _ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> Rgb {
        self.eval(wo, wi)
    }

    fn sample_f(&self, _ctx: &BsdfContext, wo: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = match &self.strategy {
            Strategy::Cosine => warp::square_to_cosine_hemisphere(u2),
            Strategy::Prepared(Prepared::Factored(f)) => f.sample(wo, u1, u2)?,
            Strategy::Prepared(Prepared::Tabulated(t)) => t.sample(wo, u1, u2)?,
            Strategy::Prepared(Prepared::Tensor(t)) => t.sample(wo, u1, u2)?,
        };
        // The density from the direction, as pdf() computes it, so that the
        // two agree to the last bit even at bin boundaries.
        BsdfSample::reflection(
            wi,
            BsdfFlags::GLOSSY | BsdfFlags::REFLECTION,
            |wi| self.eval_pdf(wo, wi),
            |wi| self.eval(wo, wi),
        )
    }

    #[inline]
    fn pdf(&self, _ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> f32 {
        self.eval_pdf(wo, wi)
    }
}
