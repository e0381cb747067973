//! The plugin contract: a plugin loaded from its library is, to the host,
//! the same plugin linked in. `contract-plugin` makes one plugin of each
//! kind whose every method, declarations with a default included, answers
//! something no default answers; the host must see each answer through
//! every wrapper it puts around a plugin (the loaded library's guard, the
//! profiler), and a panic in any method, `Light::kind` included, is an
//! error in the fault sink, never an abort.

use contract_plugin::answers::*;
use lumis_core::bsdf::{BsdfEvalLanes, BsdfSampleLanes};
use lumis_core::doc::{Table, Value};
use lumis_core::lanes::{LaneMask, Vec2Lanes, Vec3Lanes, LANES};
use lumis_core::light::LightSampleLanes;
use lumis_core::wrap::Wrapped;
use lumis_core::{
    Bsdf, BsdfContext, BsdfScope, DenoiseInput, Denoiser, Integrator, Light, LightInput,
    LightSampleContext, LightSampler, LightShape, Location, Pinhole, PluginEntity, PluginInterface,
    PluginKind, Ray, Registry, RenderStats, Rgb, Sampler, Scene, SurfaceInteraction, Texture,
    TextureQuery, UVec2, Vec2, Vec3,
};
use lumis_render::profile::{InStage, Stage};
use lumis_tests::build_plugin;

/// `contract` of `P`'s kind, with `entries` as its table.
fn make<P: PluginInterface + ?Sized>(
    registry: &Registry,
    input: P::Input<'_>,
    entries: Vec<(&str, Value)>,
) -> P::Made {
    let table = Table::built(&Location::Builtin, entries);
    let entity = PluginEntity::new(
        P::KIND,
        "the contract",
        "contract",
        table,
        Location::Builtin,
    );
    registry
        .create::<P>(&entity, input)
        .unwrap_or_else(|e| panic!("{}: {e}", P::KIND))
}

/// The same plugins linked into this test, and loaded from their library.
fn linked_and_loaded() -> [(&'static str, Registry); 2] {
    let mut linked = Registry::new();
    contract_plugin::register(&mut linked).unwrap();
    let library = build_plugin("contract-plugin", "contract_plugin");
    let mut loaded = Registry::new();
    lumis_loader::load_library(&library, &mut loaded).unwrap();
    [("linked", linked), ("loaded", loaded)]
}

/// A scene with nothing in it, for the integrator's calls.
struct Empty;

impl Scene for Empty {
    fn intersect(&self, _: &Ray) -> Option<SurfaceInteraction<'_>> {
        None
    }
    fn occluded(&self, _: &Ray) -> bool {
        false
    }
    fn lights(&self) -> &[Box<dyn Light>] {
        &[]
    }
    fn infinite_lights(&self) -> &[u32] {
        &[]
    }
    fn light_sampler(&self) -> &dyn LightSampler {
        &lumis_core::light_sampler::NoLights
    }
}

fn check_bsdf(bsdf: &dyn Bsdf, how: &str) {
    let ctx = BsdfContext::default();
    let (wo, wi) = (Vec3::Z, Vec3::Z);
    assert_eq!(bsdf.flags(), BSDF_FLAGS, "{how}");
    assert_eq!(bsdf.f(&ctx, wo, wi), BSDF_F, "{how}");
    assert_eq!(bsdf.pdf(&ctx, wo, wi), BSDF_PDF, "{how}");
    assert_eq!(bsdf.eval(&ctx, wo, wi), BSDF_EVAL, "{how}");
    assert_eq!(
        bsdf.sample_f(&ctx, wo, 0.5, Vec2::ZERO),
        Some(BSDF_SAMPLE),
        "{how}"
    );
    assert!(bsdf.uses_tangent_frame(), "{how}");
    let mut sampled = [None; 2];
    bsdf.sample_f_batch(
        &[ctx; 2],
        &[wo; 2],
        &[0.5; 2],
        &[Vec2::ZERO; 2],
        &mut sampled,
    );
    assert_eq!(sampled, [Some(BSDF_SAMPLE_BATCH); 2], "{how}");
    let mut evaluated = [(Rgb::BLACK, 0.0); 2];
    bsdf.eval_batch(&[ctx; 2], &[wo; 2], &[wi; 2], &mut evaluated);
    assert_eq!(evaluated, [BSDF_EVAL_BATCH; 2], "{how}");
    // Lanes 1 and 6 asked; the others keep what they held.
    let active = LaneMask::lane(1) | LaneMask::lane(6);
    let (w, u2) = (Vec3Lanes::default(), Vec2Lanes::default());
    let mut samples = BsdfSampleLanes::default();
    samples.set(0, Some(BSDF_SAMPLE));
    bsdf.sample_f_lanes(&[ctx; LANES], &w, &[0.5; LANES], &u2, active, &mut samples);
    assert_eq!(samples.valid, active | LaneMask::lane(0), "{how}");
    assert_eq!(samples.get(0), Some(BSDF_SAMPLE), "{how}");
    assert_eq!(samples.get(6), Some(BSDF_SAMPLE_LANES), "{how}");
    let mut evals = BsdfEvalLanes::default();
    bsdf.eval_lanes(&[ctx; LANES], &w, &w, active, &mut evals);
    assert_eq!(evals.valid, active, "{how}");
    assert_eq!(evals.get(1), BSDF_EVAL_LANES, "{how}");
}

fn check_texture(texture: &dyn Texture, how: &str) {
    let query = TextureQuery::at(Vec2::ZERO);
    assert_eq!(texture.eval(&query), TEXTURE_EVAL, "{how}");
    assert_eq!(texture.eval_float(&query), TEXTURE_FLOAT, "{how}");
    assert!(texture.uses_footprint(), "{how}");
    assert_eq!(texture.memory_bytes(), TEXTURE_BYTES, "{how}");
}

fn check_light(light: &mut dyn Light, how: &str) {
    let ctx = LightSampleContext::at(Vec3::ZERO);
    assert_eq!(light.kind(), LIGHT_KIND, "{how}");
    assert_eq!(
        light.sample_li(&ctx, Vec2::ZERO),
        Some(LIGHT_SAMPLE),
        "{how}"
    );
    let mut sampled = [None; 2];
    light.sample_li_batch(&[ctx; 2], &[Vec2::ZERO; 2], &mut sampled);
    assert_eq!(sampled, [Some(LIGHT_SAMPLE_BATCH); 2], "{how}");
    let mut lanes = LightSampleLanes::default();
    let active = LaneMask::lane(2) | LaneMask::lane(7);
    light.sample_li_lanes(&[ctx; LANES], &Vec2Lanes::default(), active, &mut lanes);
    assert_eq!(lanes.valid, active, "{how}");
    assert_eq!(lanes.get(7), Some(LIGHT_SAMPLE_LANES), "{how}");
    assert_eq!(
        light.sample_le(Vec2::ZERO, Vec2::ZERO),
        Some(LIGHT_EMISSION),
        "{how}"
    );
    assert_eq!(light.pdf_li(&ctx, Vec3::Y), LIGHT_PDF, "{how}");
    assert_eq!(
        light.l(Vec3::ZERO, Vec3::Z, Vec2::ZERO, Vec3::Z),
        LIGHT_L,
        "{how}"
    );
    assert_eq!(light.power(), LIGHT_POWER, "{how}");
    assert_eq!(light.bounds(), Some(light_bounds()), "{how}");
    assert_eq!(light.memory_bytes(), LIGHT_BYTES, "{how}");
    light.preprocess(Vec3::ZERO, 2.5);
    assert_eq!(
        light.power(),
        Rgb::splat(2.5),
        "{how}: preprocess reached the light"
    );
}

fn check_light_sampler(sampler: &dyn LightSampler, how: &str) {
    let ctx = LightSampleContext::at(Vec3::ZERO);
    assert_eq!(sampler.sample(&ctx, 0.5), Some(PICKED), "{how}");
    assert_eq!(sampler.pmf(&ctx, 0), PMF, "{how}");
}

fn check_sampler(sampler: &mut dyn Sampler, how: &str) {
    assert_eq!(sampler.samples_per_pixel(), SPP, "{how}");
    sampler.start_pixel_sample(UVec2::ZERO, 0, 1);
    assert_eq!(sampler.get_pixel_2d(), PIXEL_2D, "{how}");
    assert_eq!(sampler.get_1d(), U1, "{how}");
    assert_eq!(sampler.get_2d(), U2, "{how}");
    assert_eq!(sampler.get_1d_2d(), U1_2D, "{how}");
    assert_eq!(sampler.pixel_pattern(), PATTERN, "{how}");
    assert_eq!(sampler.randomized(), RANDOMIZED, "{how}");
    let mut clone = sampler.clone_sampler();
    assert_eq!(clone.get_1d_2d(), U1_2D, "{how}: the clone");
    assert_eq!(clone.pixel_pattern(), PATTERN, "{how}: the clone");
    let mut lanes = sampler.lanes(3);
    assert_eq!(lanes.len(), 3, "{how}");
    let mut out = [(0.0, Vec2::ZERO); 2];
    lanes.get_1d_2d_batch(&[0, 2], &mut out);
    assert_eq!(out, [LANES_1D_2D; 2], "{how}: the sampler's own lanes");
    lanes.with_lane(1, |lane| {
        assert_eq!(lane.get_1d_2d(), U1_2D, "{how}: one lane");
        assert_eq!(lane.pixel_pattern(), PATTERN, "{how}: one lane");
    });
}

fn check_integrator(integrator: &dyn Integrator, lanes_of: &dyn Sampler, how: &str) {
    let ray = Ray::new(Vec3::ZERO, Vec3::Z);
    let mut stats = RenderStats::default();
    let mut sampler = lanes_of.clone_sampler();
    assert_eq!(
        integrator.li(&ray, &Empty, sampler.as_mut(), &mut stats),
        LI,
        "{how}"
    );
    assert!(integrator.splats(), "{how}");
    let camera = Pinhole {
        origin: Vec3::ZERO,
        forward: Vec3::Z,
        top_left: Vec3::new(-1.0, 1.0, 1.0),
        per_pixel_x: Vec3::X,
        per_pixel_y: -Vec3::Y,
        resolution: UVec2::new(2, 2),
    };
    let mut splats = Vec::new();
    let li = integrator.li_splat(
        &ray,
        &Empty,
        &camera,
        sampler.as_mut(),
        &mut |raster, l| splats.push((raster, l)),
        &mut stats,
    );
    assert_eq!((li, splats), (LI_SPLAT, vec![SPLAT]), "{how}");
    assert_eq!(integrator.batch_size(), BATCH_SIZE, "{how}");
    let mut lanes = lanes_of.lanes(2);
    let mut out = [Rgb::BLACK; 2];
    integrator.li_batch(&[ray; 2], &Empty, lanes.as_mut(), &mut stats, &mut out);
    assert_eq!(out, [LI_BATCH; 2], "{how}");
}

fn check_denoiser(denoiser: &dyn Denoiser, how: &str) {
    let input = DenoiseInput {
        width: 2,
        height: 1,
        color: &[[1.0; 3]; 2],
        albedo: None,
        normal: None,
    };
    assert_eq!(
        denoiser.denoise(&input).unwrap(),
        vec![DENOISED; 2],
        "{how}"
    );
}

/// Every answer of every plugin kind, from the plugin as the registry made
/// it (linked in, or guarded from its library), and through the
/// profiler's wrappers around that.
#[test]
fn the_host_sees_every_answer_of_a_loaded_plugin() {
    let profiled = || InStage(Stage::Bsdf);
    for (origin, registry) in linked_and_loaded() {
        let bsdf = make::<dyn Bsdf>(&registry, BsdfScope::EMPTY, vec![]);
        check_bsdf(bsdf.as_ref(), origin);
        check_bsdf(
            &Wrapped::new(bsdf, profiled()),
            &format!("{origin}, profiled"),
        );

        let texture = make::<dyn Texture>(&registry, (), vec![]);
        check_texture(texture.as_ref(), origin);
        check_texture(
            &Wrapped::new(texture, profiled()),
            &format!("{origin}, profiled"),
        );

        let light_input = LightInput::untextured(&LightShape::None);
        let mut light = make::<dyn Light>(&registry, light_input, vec![]);
        check_light(light.as_mut(), origin);
        let light = make::<dyn Light>(&registry, light_input, vec![]);
        check_light(
            &mut Wrapped::new(light, profiled()),
            &format!("{origin}, profiled"),
        );

        let picker = make::<dyn LightSampler>(&registry, &[], vec![]);
        check_light_sampler(picker.as_ref(), origin);
        check_light_sampler(
            &Wrapped::new(picker, profiled()),
            &format!("{origin}, profiled"),
        );

        let mut sampler = make::<dyn Sampler>(&registry, (), vec![]);
        check_sampler(sampler.as_mut(), origin);
        let mut profiled_sampler = Wrapped::new(sampler.clone_sampler(), profiled());
        check_sampler(&mut profiled_sampler, &format!("{origin}, profiled"));

        let integrator = make::<dyn Integrator>(&registry, (), vec![]);
        check_integrator(integrator.as_ref(), sampler.as_ref(), origin);
        let wrapped = Wrapped::new(integrator, profiled());
        check_integrator(&wrapped, sampler.as_ref(), &format!("{origin}, profiled"));

        let denoiser = make::<dyn Denoiser>(&registry, (), vec![]);
        check_denoiser(denoiser.as_ref(), origin);
        check_denoiser(
            &Wrapped::new(denoiser, profiled()),
            &format!("{origin}, profiled"),
        );

        registry.faults().check().unwrap();
    }
}

/// A panic in a declaration (`Light::kind`) is contained like one in any
/// other method: recorded, named, answered neutrally.
#[test]
fn a_panic_in_a_declaration_is_an_error() {
    let [_, (_, loaded)] = linked_and_loaded();
    let input = LightInput::untextured(&LightShape::None);
    let light = make::<dyn Light>(&loaded, input, vec![("panic_in_kind", Value::from(true))]);
    let _ = light.kind();
    let err = loaded.faults().check().unwrap_err().to_string();
    assert!(
        err.contains("panicked in Light::kind: the fixture panics in kind as asked"),
        "{err}"
    );
}

/// Two plugin crates link into one binary: each exports its entry point
/// under its own crate's name.
#[test]
fn two_plugin_crates_link_into_one_binary() {
    let mut registry = Registry::new();
    contract_plugin::register(&mut registry).unwrap();
    example_bsdf::register(&mut registry).unwrap();
    assert!(registry.find(PluginKind::Bsdf, "contract").is_some());
    assert_eq!(registry.names(PluginKind::Bsdf).len(), 2);
}
