//! Standard integrators: `path` (unidirectional path tracing), `direct`
//! (direct lighting only), `wavefront` and `packet` (`path`'s estimator
//! on many paths at once), sharing one direct-lighting estimator, and
//! `light` (particle tracing, from the lights to the camera).

mod direct;
mod estimator;
mod light;
mod packet;
mod path;
mod path_state;
mod specialize;
mod wavefront;

pub use direct::DirectIntegrator;
pub use estimator::{
    Estimator, EstimatorParams, Heuristic, HeuristicName, MisEstimator, SceneView, Strategy,
    VertexPlan,
};
pub use light::{LightTracer, LightTracerParams};
pub use packet::{PacketIntegrator, PacketParams};
pub use path::{PathIntegrator, PathParams};
pub use specialize::{Specialized, Trace};
pub use wavefront::{WavefrontIntegrator, WavefrontParams};

use lumis_api::{Registrar, Result, Scene};

/// Registers every integrator of this crate.
pub fn register(registry: &mut dyn Registrar) -> Result<()> {
    registry.add_integrator(path::SPEC, |p| {
        Ok(Box::new(PathIntegrator::from_params(p)?))
    })?;
    registry.add_integrator(direct::SPEC, |p| {
        Ok(Box::new(DirectIntegrator::from_params(p)?))
    })?;
    registry.add_integrator(wavefront::SPEC, |p| {
        Ok(Box::new(WavefrontIntegrator::from_params(p)?))
    })?;
    registry.add_integrator(packet::SPEC, |p| {
        Ok(Box::new(PacketIntegrator::from_params(p)?))
    })?;
    registry.add_integrator(light::SPEC, |p| Ok(Box::new(LightTracer::from_params(p)?)))
}

/// As [`register`], with each integrator's loop also compiled for the scene
/// type `S`, so that its queries inline into the loop: the binary passes
/// its own scene type, which this crate cannot name.
pub fn register_specialized<S: Scene + 'static>(registry: &mut dyn Registrar) -> Result<()> {
    registry.add_integrator(path::SPEC, |p| {
        Ok(Box::new(Specialized::<_, S>::new(
            PathIntegrator::from_params(p)?,
        )))
    })?;
    registry.add_integrator(direct::SPEC, |p| {
        Ok(Box::new(Specialized::<_, S>::new(
            DirectIntegrator::from_params(p)?,
        )))
    })?;
    // Their scene queries are one virtual call per wave or packet, not per
    // ray: they need no loop compiled for the scene type.
    registry.add_integrator(wavefront::SPEC, |p| {
        Ok(Box::new(WavefrontIntegrator::from_params(p)?))
    })?;
    registry.add_integrator(packet::SPEC, |p| {
        Ok(Box::new(PacketIntegrator::from_params(p)?))
    })?;
    registry.add_integrator(light::SPEC, |p| Ok(Box::new(LightTracer::from_params(p)?)))
}
