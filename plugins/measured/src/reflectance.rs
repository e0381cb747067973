//! What a `measured` material renders: the MERL table, or its tensor
//! approximation ([`crate::tensor`]). The samplers are built from the same
//! values the material renders, so that they follow the reflectance a
//! render sees, and a tensor render needs no table once it is fitted.

use std::sync::Arc;

use lumis_api::{Rgb, Vec3};

use crate::merl::{content_hash, MerlTable};
use crate::tensor::TensorBrdf;

#[derive(Debug, Clone)]
pub enum Reflectance {
    Table(Arc<MerlTable>),
    Tensor(Arc<TensorBrdf>),
}

impl Reflectance {
    /// `f(wi, wo)`, for both directions in the upper hemisphere.
    #[inline]
    pub fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        match self {
            Reflectance::Table(t) => t.eval(wi, wo),
            Reflectance::Tensor(t) => t.eval(wi, wo),
        }
    }

    /// A hash of what defines the values (the table file's content, or
    /// the factors'), which keys the samplers' cache.
    pub fn hash(&self) -> u64 {
        match self {
            Reflectance::Table(t) => t.hash(),
            Reflectance::Tensor(t) => {
                let bytes: Vec<u8> = t.payload().iter().flat_map(|v| v.to_le_bytes()).collect();
                content_hash(&bytes)
            }
        }
    }

    /// Bytes held.
    pub fn memory_bytes(&self) -> usize {
        match self {
            Reflectance::Table(t) => t.memory_bytes(),
            Reflectance::Tensor(t) => t.memory_bytes(),
        }
    }
}
