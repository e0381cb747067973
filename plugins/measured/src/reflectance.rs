//! What a `measured` material renders: the MERL table, its tensor
//! approximation ([`crate::tensor`]), or an analytic BSDF that the
//! samplers and the tensor are fitted to directly. The samplers are built
//! from the same values the material renders, so that they follow the
//! reflectance a render sees, and a tensor render needs no table once it
//! is fitted.

use std::sync::Arc;

use lumis_api::params::NestedBsdf;
use lumis_api::{BsdfContext, Rgb, Vec3};

use crate::merl::{content_hash, MerlTable};
use crate::tensor::TensorBrdf;

#[derive(Debug, Clone)]
pub enum Reflectance {
    Table(Arc<MerlTable>),
    Tensor(Arc<TensorBrdf>),
    /// A lumis BSDF evaluated wherever a value is asked for: the ground
    /// truth a table would be tabulated from, with no table in between.
    Analytic(NestedBsdf),
}

impl Reflectance {
    /// `f(wi, wo)`, for both directions in the upper hemisphere.
    #[inline]
    pub fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        match self {
            Reflectance::Table(t) => t.eval(wi, wo),
            Reflectance::Tensor(t) => t.eval(wi, wo),
            Reflectance::Analytic(b) => b.0.f(&BsdfContext::default(), wo, wi),
        }
    }

    /// A hash of what defines the values (the table file's content, or
    /// the factors'), which keys the samplers' cache; `None` for an
    /// analytic BSDF, whose precomputations are not cached.
    pub fn cache_hash(&self) -> Option<u64> {
        match self {
            Reflectance::Table(t) => Some(t.hash()),
            Reflectance::Tensor(t) => {
                let bytes: Vec<u8> = t.payload().iter().flat_map(|v| v.to_le_bytes()).collect();
                Some(content_hash(&bytes))
            }
            Reflectance::Analytic(_) => None,
        }
    }

    /// Bytes held (an analytic BSDF's own parameters not counted).
    pub fn memory_bytes(&self) -> usize {
        match self {
            Reflectance::Table(t) => t.memory_bytes(),
            Reflectance::Tensor(t) => t.memory_bytes(),
            Reflectance::Analytic(_) => 0,
        }
    }
}
