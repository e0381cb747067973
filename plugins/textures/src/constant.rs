//! `constant`: one value everywhere.

use lumis_api::{Params, PluginKind, PluginParams, PluginSpec, Result, Rgb, Texture, TextureQuery};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Texture,
    name: "constant",
    source: lumis_api::source_file!(),
    doc: "one value everywhere",
    params: ConstantParams::SPECS,
};

#[derive(Debug, Clone, Copy, PluginParams)]
pub struct ConstantParams {
    /// the value, linear RGB (one number for grey)
    pub value: Rgb,
}

#[derive(Debug, Clone, Copy)]
pub struct Constant(pub Rgb);

impl Constant {
    pub fn from_params(params: &Params) -> Result<Self> {
        Ok(Self(ConstantParams::read(params)?.value))
    }
}

impl Texture for Constant {
    #[inline]
    fn eval(&self, _query: &TextureQuery) -> Rgb {
        self.0
    }
}
