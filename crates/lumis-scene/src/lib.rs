//! From a TOML scene file to a render-ready scene.
//!
//! The loader reads the document (with locations for every key), applies
//! `--set` overrides, instantiates only the plugins the scene names through
//! the [`Registry`], loads geometry into Embree, and creates an area light
//! for every emissive shape.

mod accel;
mod gltf;
mod render_scene;
mod report;
mod scene_hash;
mod shapes;
mod transform;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use lumis_core::doc::{self, Node, Table, Value};
use lumis_core::registry::TableRef;
use lumis_core::{
    Bsdf, Error, Integrator, Light, LightKind, LightSampler, LightShape, Location, ParamSpec,
    ParamType, ParamValue, Params, Registry, Result, Sampler, UVec2, Vec3,
};
use lumis_embree::{Device, PaddedBuffer, SceneBuilder, SceneOptions};
use lumis_render::PerspectiveCamera;

pub use accel::{Compaction, AUTO_COMPACT_TRIANGLES};
pub use render_scene::{LoadReport, RenderScene, SceneCounts};
pub use scene_hash::{scene_hash, Fnv1a};

use render_scene::{Geometry, MeshData, Placement, Prototype, SceneBsdf, NO_LIGHT};
use report::Phase;
use shapes::{ShapeDesc, ShapeGeometry, SHAPE_TYPES};

/// Everything `lumis render` needs.
pub struct LoadedScene {
    /// The scene file's stem, e.g. `cornell-box`.
    pub name: String,
    pub scene: RenderScene,
    pub camera: PerspectiveCamera,
    pub sampler: Box<dyn Sampler>,
    pub integrator: Box<dyn Integrator>,
    pub seed: u64,
    /// `film.output`, resolved against the scene file's directory.
    pub output: Option<PathBuf>,
}

const TOP_LEVEL_KEYS: &[&str] = &[
    "film",
    "camera",
    "sampler",
    "integrator",
    "light_sampler",
    "bsdf",
    "shape",
    "light",
    "seed",
    "plugins",
    "accel",
];

/// A scene under construction: the Embree builder and everything shading
/// will index by the geometry ids Embree hands out.
pub(crate) struct Assembly<'r> {
    pub registry: &'r Registry,
    pub device: Device,
    /// Quality and robustness for every BVH; `compaction` is decided once
    /// every shape is counted, and applied by [`build_bvhs`].
    pub options: SceneOptions,
    pub compaction: Compaction,
    pub builder: SceneBuilder,
    /// Indexed by top-level geometry id: one entry per `builder.add_*`.
    pub geometries: Vec<Geometry>,
    /// Instanced meshes, built with the top-level scene by [`build_bvhs`].
    pub pending: Vec<PendingPrototype>,
    pub lights: Vec<Box<dyn Light>>,
    pub bsdfs: Vec<(String, Arc<dyn Bsdf>)>,
    pub counts: SceneCounts,
    pub report: LoadReport,
}

const PLUGINS_PARAMS: &[ParamSpec] = &[ParamSpec::with_default(
    "load",
    ParamType::StringArray,
    ParamValue::Array(&[]),
    "plugin libraries to load, relative to the scene file",
)];

const FILM_PARAMS: &[ParamSpec] = &[
    ParamSpec::with_default(
        "resolution",
        ParamType::UIntPair,
        ParamValue::Array(&[ParamValue::Int(256), ParamValue::Int(256)]),
        "image width and height in pixels",
    ),
    ParamSpec::optional(
        "output",
        ParamType::String,
        "output EXR path, relative to the scene file",
    ),
    ParamSpec::optional(
        "filter",
        ParamType::Table,
        "pixel filter: { type = \"box\" } (the default)",
    ),
];

const CAMERA_PARAMS: &[ParamSpec] = &[
    ParamSpec::required("origin", ParamType::Vec3, "eye position"),
    ParamSpec::required("target", ParamType::Vec3, "point looked at"),
    ParamSpec::with_default(
        "up",
        ParamType::Vec3,
        ParamValue::Array(&[
            ParamValue::Float(0.0),
            ParamValue::Float(1.0),
            ParamValue::Float(0.0),
        ]),
        "up direction",
    ),
    ParamSpec::required(
        "fov",
        ParamType::Float,
        "full angle of the smaller image axis, degrees, in (0, 180)",
    ),
];

/// Reads and loads a scene file.
pub fn load_file(path: &Path, overrides: &[String], registry: &Registry) -> Result<LoadedScene> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::msg(format!("cannot read scene '{}': {e}", path.display())))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    load_str(
        &text,
        &path.display().to_string(),
        &name,
        dir,
        overrides,
        registry,
    )
}

/// Loads a scene from TOML text; `label` names it in error locations and
/// relative paths resolve against `dir`.
pub fn load_str(
    text: &str,
    label: &str,
    name: &str,
    dir: &Path,
    overrides: &[String],
    registry: &Registry,
) -> Result<LoadedScene> {
    let parse_start = std::time::Instant::now();
    let mut root = doc::parse(text, label)?;
    let parse_time = parse_start.elapsed();
    for assignment in overrides {
        doc::apply_override(&mut root, assignment)?;
    }
    let file_location = Location::File {
        path: Arc::from(label),
        line: 1,
        column: 1,
    };
    check_top_level_keys(&root)?;
    let seed = seed_of(&root)?;
    // Plugins the scene loads go into a copy of the registry: the caller's
    // stays as it was, and nothing but what this scene names is registered.
    let scene_registry = with_scene_plugins(&root, registry, dir)?;
    let registry = scene_registry.as_ref().unwrap_or(registry);

    let (camera, output) = film_and_camera(&root, &file_location, dir)?;
    let bsdfs = named_bsdfs(&root, registry)?;
    let device = device()?;
    let accel = accel::accel_options(&root)?;
    let mut asm = Assembly {
        registry,
        builder: SceneBuilder::new(&device, accel.embree).map_err(embree_error)?,
        device,
        options: accel.embree,
        compaction: accel.compaction,
        geometries: Vec::new(),
        pending: Vec::new(),
        lights: Vec::new(),
        bsdfs,
        counts: SceneCounts::default(),
        report: LoadReport {
            parse: parse_time,
            ..LoadReport::default()
        },
    };
    let memory_before = asm.device.memory_in_use();

    for (i, (table, location)) in tables_in(&root, "shape")?.into_iter().enumerate() {
        let owner = format!("[[shape]] #{}", i + 1);
        let (kind, kind_location) = type_of(table, &location, &owner)?;
        let spec = SHAPE_TYPES
            .iter()
            .find(|(n, _)| *n == kind)
            .map(|(_, s)| *s)
            .ok_or_else(|| shapes::unknown_shape_type(kind, &kind_location))?;
        let owner = format!("{owner} (type = \"{kind}\")");
        let params = Params::new(owner.clone(), table, location.clone(), spec, &["type"])?;
        if kind == "gltf" {
            let shape = gltf::parse(&owner, &params, table, dir)?;
            params.finish()?;
            gltf::add(&owner, shape, &mut asm)?;
            continue;
        }
        let desc = asm.report.time(Phase::Parse, || {
            shapes::parse_shape(kind, &params, table, dir)
        })?;
        params.finish()?;
        let geometry = add_shape(&owner, desc, &mut asm)?;
        asm.geometries.push(geometry);
    }
    for (i, (table, location)) in tables_in(&root, "light")?.into_iter().enumerate() {
        let light = PluginTable::new(format!("[[light]] #{}", i + 1), table, location)?;
        asm.lights
            .push(registry.create_light(&light.as_ref(), &LightShape::None)?);
    }

    let Assembly {
        builder,
        device,
        compaction,
        mut geometries,
        pending,
        mut lights,
        bsdfs,
        mut counts,
        mut report,
        ..
    } = asm;
    report.compaction = compaction;
    report.compact = compaction.decide(counts.unique_triangles);
    if !report.compact {
        // Scenes that keep the fast BVH also keep flat meshes' frames; a
        // compact scene is one whose memory matters more.
        for geometry in &mut geometries {
            if let Geometry::Mesh(mesh) = geometry {
                mesh.store_flat_frames();
            }
        }
    }
    let (embree, prototypes) = build_bvhs(builder, pending, &mut geometries, &mut report)?;
    report.bvh_bytes = (device.memory_in_use() - memory_before).max(0) as usize;
    report.geometry_bytes = geometry_bytes(&geometries, &prototypes);
    geometries.shrink_to_fit();
    let (center, radius) = render_scene::bounding_sphere(&embree);
    let infinite_lights = classify_lights(&mut lights, center, radius, &mut counts);
    let light_sampler = light_sampler_of(&root, registry, &lights)?;
    let sampler = registry
        .create_sampler(&PluginTable::required(&root, "sampler", &file_location)?.as_ref())?;
    let integrator = registry
        .create_integrator(&PluginTable::required(&root, "integrator", &file_location)?.as_ref())?;

    let scene = RenderScene {
        embree,
        geometries,
        prototypes,
        bsdfs: bsdfs.into_iter().map(|(_, b)| SceneBsdf::new(b)).collect(),
        lights,
        infinite_lights,
        light_sampler,
        counts,
        report,
        packets: accel.packets,
    };
    Ok(LoadedScene {
        name: name.to_string(),
        scene,
        camera,
        sampler,
        integrator,
        seed,
        output,
    })
}

/// Bytes of geometry data held for shading and shared with Embree.
fn geometry_bytes(geometries: &[Geometry], prototypes: &[Prototype]) -> usize {
    let own: usize = geometries
        .iter()
        .map(|g| match g {
            Geometry::Mesh(m) => m.byte_size(),
            Geometry::Instance { lights, .. } => {
                lights.iter().map(|l| l.capacity() * 4).sum::<usize>()
                    + std::mem::size_of::<Geometry>()
            }
            Geometry::Sphere { .. } => std::mem::size_of::<Geometry>(),
        })
        .sum();
    own + prototypes
        .iter()
        .flat_map(|p| &p.meshes)
        .map(MeshData::byte_size)
        .sum::<usize>()
}

/// A mesh used by several nodes: its own Embree scene, built with the
/// top-level one once the scene-wide build options are known.
pub(crate) struct PendingPrototype {
    pub builder: SceneBuilder,
    pub meshes: Vec<MeshData>,
    pub instances: Vec<PendingInstance>,
    /// Prefixes a build error: the shape and file it came from.
    pub owner: String,
    pub location: Location,
}

/// One node's placement of a [`PendingPrototype`].
pub(crate) struct PendingInstance {
    /// 3x4 column-major, as Embree takes it.
    pub transform: [f32; 12],
    pub placement: Placement,
    /// Per prototype mesh, the instance's light index per triangle.
    pub lights: Vec<Vec<u32>>,
}

/// Builds the instanced meshes' BVHs (in parallel), places their
/// instances and builds the top level, all compact or not as
/// `report.compact` says. Returns the scene and the prototypes, indexed
/// as the instances' `prototype`.
fn build_bvhs(
    mut builder: SceneBuilder,
    pending: Vec<PendingPrototype>,
    geometries: &mut Vec<Geometry>,
    report: &mut LoadReport,
) -> Result<(lumis_embree::Scene, Vec<Prototype>)> {
    let compact = report.compact;
    let (builders, rest): (Vec<_>, Vec<_>) = pending
        .into_iter()
        .map(|mut p| {
            p.builder.set_compact(compact);
            (p.builder, (p.meshes, p.instances, p.owner, p.location))
        })
        .unzip();
    let scenes = report.time(Phase::Bvh, || {
        use rayon::prelude::*;
        builders
            .into_par_iter()
            .map(SceneBuilder::commit)
            .collect::<Vec<_>>()
    });
    let mut prototypes = Vec::with_capacity(scenes.len());
    for (scene, (meshes, instances, owner, location)) in scenes.into_iter().zip(rest) {
        let err = |e: lumis_embree::EmbreeError| Error::at(&location, format!("{owner}: {e}"));
        let scene = Arc::new(scene.map_err(err)?);
        let prototype = prototypes.len() as u32;
        for instance in instances {
            builder
                .add_instance(scene.clone(), &instance.transform)
                .map_err(err)?;
            geometries.push(Geometry::Instance {
                prototype,
                placement: instance.placement,
                lights: instance.lights,
            });
        }
        prototypes.push(Prototype { meshes });
    }
    builder.set_compact(compact);
    let embree = report.time(Phase::Bvh, || builder.commit().map_err(embree_error))?;
    Ok((embree, prototypes))
}

fn check_top_level_keys(root: &Table) -> Result<()> {
    match root
        .entries
        .iter()
        .find(|e| !TOP_LEVEL_KEYS.contains(&e.key.as_str()))
    {
        Some(entry) => Err(Error::at(
            &entry.key_location,
            format!(
                "unknown top-level key '{}'; accepted: {}",
                entry.key,
                TOP_LEVEL_KEYS.join(", ")
            ),
        )),
        None => Ok(()),
    }
}

fn seed_of(root: &Table) -> Result<u64> {
    match root.get("seed") {
        None => Ok(0),
        Some(node) => match node.value {
            Value::Int(s) if s >= 0 => Ok(s as u64),
            _ => Err(Error::at(
                &node.location,
                "seed: expected a non-negative integer",
            )),
        },
    }
}

/// A copy of `registry` extended with the libraries of `[plugins] load`,
/// or `None` when the scene loads none.
fn with_scene_plugins(root: &Table, registry: &Registry, dir: &Path) -> Result<Option<Registry>> {
    let Some(node) = root.get("plugins") else {
        return Ok(None);
    };
    let table = as_table(node, "plugins")?;
    let params = Params::new(
        "[plugins]",
        table,
        node.location.clone(),
        PLUGINS_PARAMS,
        &[],
    )?;
    let libraries: Vec<String> = params.get("load")?;
    let mut extended = registry.clone();
    for library in libraries {
        lumis_loader::load_library(&dir.join(&library), &mut extended)
            .map_err(|e| params.error("load", e.message))?;
    }
    params.finish()?;
    Ok(Some(extended))
}

/// Hands infinite lights the scene bounds, counts lights by kind and
/// returns the indices of the infinite ones.
fn classify_lights(
    lights: &mut [Box<dyn Light>],
    center: Vec3,
    radius: f32,
    counts: &mut SceneCounts,
) -> Vec<u32> {
    let mut infinite = Vec::new();
    for (i, light) in lights.iter_mut().enumerate() {
        light.preprocess(center, radius);
        match light.kind() {
            LightKind::Infinite => {
                infinite.push(i as u32);
                counts.infinite_lights += 1;
            }
            LightKind::DeltaPosition => counts.delta_lights += 1,
            LightKind::Area => {}
        }
    }
    infinite
}

/// The `[light_sampler]` table's plugin, `uniform` when absent.
fn light_sampler_of(
    root: &Table,
    registry: &Registry,
    lights: &[Box<dyn Light>],
) -> Result<Box<dyn LightSampler>> {
    let default_table = Table::default();
    let (table, location) = match root.get("light_sampler") {
        Some(node) => (as_table(node, "light_sampler")?, node.location.clone()),
        None => (&default_table, Location::Builtin),
    };
    let (kind, kind_location) = match table.get("type") {
        Some(_) => type_of(table, &location, "light_sampler")?,
        None => ("uniform", Location::Builtin),
    };
    registry.create_light_sampler(
        &TableRef {
            owner: "light_sampler",
            table,
            location: &location,
            type_name: kind,
            type_location: &kind_location,
            structural: &["type"],
        },
        lights,
    )
}

/// A plugin table of the scene with its `type` resolved.
struct PluginTable<'a> {
    owner: String,
    table: &'a Table,
    location: Location,
    kind: &'a str,
    kind_location: Location,
}

impl<'a> PluginTable<'a> {
    fn new(owner: String, table: &'a Table, location: Location) -> Result<Self> {
        let (kind, kind_location) = type_of(table, &location, &owner)?;
        Ok(Self {
            owner,
            table,
            location,
            kind,
            kind_location,
        })
    }

    /// The top-level table `key`, which the scene must have.
    fn required(root: &'a Table, key: &str, file: &Location) -> Result<Self> {
        let (table, location) = required_table(root, key, file)?;
        Self::new(key.to_string(), table, location)
    }

    fn as_ref(&self) -> TableRef<'_> {
        TableRef {
            owner: &self.owner,
            table: self.table,
            location: &self.location,
            type_name: self.kind,
            type_location: &self.kind_location,
            structural: &["type"],
        }
    }
}

fn device() -> Result<Device> {
    Device::new().map_err(embree_error)
}

fn embree_error(e: lumis_embree::EmbreeError) -> Error {
    Error::msg(e.to_string())
}

fn as_table<'a>(node: &'a Node, what: &str) -> Result<&'a Table> {
    match &node.value {
        Value::Table(t) => Ok(t),
        v => Err(Error::at(
            &node.location,
            format!("{what}: expected a table, found {}", v.type_name()),
        )),
    }
}

fn required_table<'a>(
    root: &'a Table,
    key: &str,
    file: &Location,
) -> Result<(&'a Table, Location)> {
    match root.get(key) {
        Some(node) => Ok((as_table(node, key)?, node.location.clone())),
        None => Err(Error::at(
            file,
            format!("the scene needs a [{key}] table with a type"),
        )),
    }
}

/// The tables of an array of tables (`[[shape]]`), with their locations.
fn tables_in<'a>(root: &'a Table, key: &str) -> Result<Vec<(&'a Table, Location)>> {
    let Some(node) = root.get(key) else {
        return Ok(Vec::new());
    };
    let Value::Array(items) = &node.value else {
        return Err(Error::at(
            &node.location,
            format!("'{key}' must be an array of tables: write [[{key}]]"),
        ));
    };
    items
        .iter()
        .map(|n| as_table(n, key).map(|t| (t, n.location.clone())))
        .collect()
}

/// The `type = "..."` of a table, with its location.
fn type_of<'a>(table: &'a Table, location: &Location, owner: &str) -> Result<(&'a str, Location)> {
    match table.get("type") {
        Some(Node {
            value: Value::String(s),
            location,
        }) => Ok((s.as_str(), location.clone())),
        Some(node) => Err(Error::at(
            &node.location,
            format!(
                "{owner}: 'type' must be a string, found {}",
                node.value.type_name()
            ),
        )),
        None => Err(Error::at(
            location,
            format!("{owner} needs a type = \"...\""),
        )),
    }
}

fn film_and_camera(
    root: &Table,
    file: &Location,
    dir: &Path,
) -> Result<(PerspectiveCamera, Option<PathBuf>)> {
    let empty = Table::default();
    let (film, film_location) = match root.get("film") {
        Some(node) => (as_table(node, "film")?, node.location.clone()),
        None => (&empty, file.clone()),
    };
    let film = Params::new("[film]", film, film_location, FILM_PARAMS, &[])?;
    let resolution: UVec2 = film.get("resolution")?;
    if resolution.x == 0 || resolution.y == 0 {
        return Err(film.error("resolution", "width and height must be at least 1"));
    }
    let output = film.get_opt::<String>("output")?.map(|o| dir.join(o));
    if let Some((filter, location)) = film.table("filter")? {
        match type_of(filter, &location, "[film] filter")? {
            ("box", _) if filter.entries.len() == 1 => {}
            ("box", _) => {
                return Err(Error::at(
                    &location,
                    "the box filter takes no parameters (radius 1/2 pixel)",
                ))
            }
            (other, loc) => {
                return Err(Error::at(
                    &loc,
                    format!("unknown pixel filter \"{other}\"; available: box"),
                ));
            }
        }
    }
    film.finish()?;

    let (table, location) = required_table(root, "camera", file)?;
    let (kind, kind_location) = type_of(table, &location, "[camera]")?;
    if kind == "gltf" {
        let camera = gltf::camera::from_table(table, location, dir, resolution)?;
        return Ok((camera, output));
    }
    if kind != "perspective" {
        return Err(Error::at(
            &kind_location,
            format!("unknown camera type \"{kind}\"; available: perspective, gltf"),
        ));
    }
    let cam = Params::new(
        "[camera] (type = \"perspective\")",
        table,
        location.clone(),
        CAMERA_PARAMS,
        &["type"],
    )?;
    let fov: f32 = cam.get("fov")?;
    if !(fov > 0.0 && fov < 180.0) {
        return Err(cam.error("fov", format!("must be in (0, 180) degrees, got {fov}")));
    }
    let camera = PerspectiveCamera::new(
        cam.get("origin")?,
        cam.get("target")?,
        cam.get("up")?,
        fov,
        resolution,
    )
    .map_err(|e| Error::at(&location, format!("[camera]: {}", e.message)))?;
    cam.finish()?;
    Ok((camera, output))
}

/// Instantiates every `[[bsdf]]`, checking names are present and unique.
fn named_bsdfs(root: &Table, registry: &Registry) -> Result<Vec<(String, Arc<dyn Bsdf>)>> {
    let mut out: Vec<(String, Arc<dyn Bsdf>)> = Vec::new();
    for (i, (table, location)) in tables_in(root, "bsdf")?.into_iter().enumerate() {
        let name = match table.get("name") {
            Some(Node {
                value: Value::String(s),
                ..
            }) => s.clone(),
            Some(node) => return Err(Error::at(&node.location, "[[bsdf]] name must be a string")),
            None => {
                return Err(Error::at(
                    &location,
                    format!(
                        "[[bsdf]] #{} needs a name = \"...\" that shapes refer to",
                        i + 1
                    ),
                ))
            }
        };
        if out.iter().any(|(n, _)| *n == name) {
            let at = &table.get("name").expect("checked above").location;
            return Err(Error::at(
                at,
                format!("a [[bsdf]] named \"{name}\" already exists"),
            ));
        }
        let owner = format!("bsdf \"{name}\"");
        let (kind, kind_location) = type_of(table, &location, &owner)?;
        let bsdf = registry.create_bsdf(&TableRef {
            owner: &owner,
            table,
            location: &location,
            type_name: kind,
            type_location: &kind_location,
            structural: &["type", "name"],
        })?;
        out.push((name, bsdf));
    }
    Ok(out)
}

/// Adds one shape to Embree and creates its area lights.
fn add_shape(owner: &str, desc: ShapeDesc, asm: &mut Assembly) -> Result<Geometry> {
    let Assembly {
        registry,
        builder,
        lights,
        bsdfs,
        counts,
        ..
    } = asm;
    let registry: &Registry = registry;
    let bsdf = bsdfs
        .iter()
        .position(|(n, _)| *n == desc.bsdf)
        .ok_or_else(|| {
            let names: Vec<&str> = bsdfs.iter().map(|(n, _)| n.as_str()).collect();
            Error::at(
                &desc.bsdf_location,
                format!(
                    "{owner}: no [[bsdf]] named \"{}\"; defined: {}",
                    desc.bsdf,
                    if names.is_empty() {
                        "none".into()
                    } else {
                        names.join(", ")
                    }
                ),
            )
        })? as u32;
    let orientation = if desc.flip_normals { -1.0 } else { 1.0 };
    let emission_owner = format!("{owner} emission");
    let emission = desc.emission.as_ref();
    let has_emission = emission.is_some();
    let mut make_light = |default_type: &str, shape: LightShape| -> Result<Option<u32>> {
        let Some((table, location)) = emission else {
            return Ok(None);
        };
        let table: &Table = table;
        let (kind, kind_location) = match table.get("type") {
            Some(_) => type_of(table, location, &emission_owner)?,
            None => (default_type, location.clone()),
        };
        let light = registry.create_light(
            &TableRef {
                owner: &emission_owner,
                table,
                location,
                type_name: kind,
                type_location: &kind_location,
                structural: &["type"],
            },
            &shape,
        )?;
        lights.push(light);
        counts.area_lights += 1;
        Ok(Some(lights.len() as u32 - 1))
    };

    match desc.geometry {
        ShapeGeometry::Mesh {
            positions,
            indices,
            normals,
            quad,
        } => {
            let light_indices = match quad {
                Some((corner, edge_u, edge_v)) => {
                    let (edge_u, edge_v) = if desc.flip_normals {
                        (edge_v, edge_u)
                    } else {
                        (edge_u, edge_v)
                    };
                    match make_light(
                        "quad",
                        LightShape::Quad {
                            corner,
                            edge_u,
                            edge_v,
                        },
                    )? {
                        Some(i) => vec![i; indices.len()],
                        None => Vec::new(),
                    }
                }
                None if has_emission => {
                    let mut per_triangle = Vec::with_capacity(indices.len());
                    for t in &indices {
                        let [a, b, c] = t.map(|i| Vec3::from(positions[i as usize]));
                        let p = if desc.flip_normals {
                            [a, c, b]
                        } else {
                            [a, b, c]
                        };
                        // Zero-area triangles cannot emit; they keep no light.
                        let degenerate = (b - a).cross(c - a).length_squared() == 0.0;
                        per_triangle.push(if degenerate {
                            NO_LIGHT
                        } else {
                            make_light("triangle", LightShape::Triangle { p })?.unwrap_or(NO_LIGHT)
                        });
                    }
                    per_triangle
                }
                None => Vec::new(),
            };
            counts.meshes += 1;
            counts.triangles += indices.len();
            counts.unique_triangles += indices.len();
            counts.shading_normals |= normals.is_some();
            let vertices = Arc::new(PaddedBuffer::new(positions));
            let indices = Arc::new(PaddedBuffer::new(indices));
            builder
                .add_triangle_mesh(vertices.clone(), indices.clone())
                .map_err(|e| Error::msg(format!("{owner}: {e}")))?;
            Ok(Geometry::Mesh(MeshData {
                vertices,
                indices,
                normals,
                uvs: None,
                bsdf,
                lights: light_indices,
                orientation,
                flat_frames: Vec::new(),
            }))
        }
        ShapeGeometry::Sphere { center, radius } => {
            let light = make_light(
                "sphere",
                LightShape::Sphere {
                    center,
                    radius,
                    inward: desc.flip_normals,
                },
            )?;
            counts.spheres += 1;
            builder
                .add_spheres(Arc::new(PaddedBuffer::new(vec![[
                    center.x, center.y, center.z, radius,
                ]])))
                .map_err(|e| Error::msg(format!("{owner}: {e}")))?;
            Ok(Geometry::Sphere {
                center,
                radius,
                bsdf,
                light,
                orientation,
            })
        }
    }
}
