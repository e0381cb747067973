"""Convert a lumis TOML scene into a Mitsuba 3 scene dictionary (`mi.load_dict`).

Only what the bench scenes use is supported; anything else raises
`Unsupported` with the table and key, never a silent approximation. The
mapping, one lumis construct at a time:

- `[film]`: `hdrfilm`, same resolution, `rfilter = box` (lumis's only filter,
  uniform over the pixel), RGB float32.
- `[camera] type = "perspective"`: `perspective`, `fov` with
  `fov_axis = "smaller"` (lumis's `fov` is the full angle of the smaller image
  axis; for landscape films that is Mitsuba's `fov_axis = "y"`), `to_world`
  from `look_at(origin, target, up)`.
- `[integrator] type = "path"`: `path` with the same `max_depth` and
  `rr_depth`. Both count path segments from the camera the same way: 1 =
  emitters seen directly, 2 = direct lighting (Mitsuba: "1 will only render
  directly visible light sources, 2 will lead to single-bounce (direct-only)
  illumination"), and both start Russian roulette after `rr_depth` segments
  (lumis survives with max(beta), Mitsuba with min(max(beta) eta^2, 0.95):
  different noise, same expectation). Mitsuba's path tracer combines BSDF and
  emitter sampling by MIS with the power heuristic, one sample each, so only
  lumis's `strategy = "mis"`, `heuristic = "power"`, `beta = 2`, `n_f = n_g =
  1`, multi-sample, are accepted.
- `[light_sampler]`: `uniform` (Mitsuba picks an emitter uniformly; an
  emissive mesh is one emitter sampled by area, which for the equal
  triangles of the bench scenes is lumis's uniform choice of triangle), and
  `bvh`, against that same default (Mitsuba 3 has no light BVH): the same
  expectation, different noise.
- BSDFs: `diffuse` (`two_sided` -> `twosided` wrapper), `conductor` (below
  roughness 1e-3 -> `conductor`, else `roughconductor` with `distribution`,
  `alpha` or `alpha_u`/`alpha_v`, `sample_visible`; `material = "none"` or
  explicit `eta`/`k`), `mirror`, `dielectric` (smooth, or `roughdielectric`),
  `plastic` (smooth, or `roughplastic`). `measured` (MERL) has no Mitsuba 3
  counterpart in its default build.
- Shapes: `obj` (`face_normals` unless the file has `vn`), `quad` ->
  `rectangle` with the affine `to_world` [edge_u/2, edge_v/2, n, centre] (the
  front, edge_u x edge_v, is the rectangle's +z), `sphere`, inline `mesh` and
  `gltf` (read here: positions, normals, TEXCOORD_0, node transforms, the TOML
  `transform`; materials as lumis maps them: metallic >= 0.5 -> conductor with
  the base colour as reflectance, else plastic with coat IOR 1.5, alpha =
  roughness^2, GGX, `doubleSided` -> `twosided`; base colour textures ->
  `bitmap`) become `mi.Mesh` objects. `emission` -> an `area` emitter
  (one-sided only: Mitsuba's area emitter has no two-sided mode).
- `[[light]]`: `point`, `constant`, `envmap` (importance sampling only;
  `up` and `rotation` become `to_world`; both renderers interpolate between
  texel centres, wrapping in u, so one file is one sky).
"""
import base64
import hashlib
import json
import math
import os
import struct

try:
    import tomllib
except ModuleNotFoundError:  # Python < 3.11
    import tomli as tomllib

import numpy as np

CONVERTER_VERSION = "1"  # bump when a conversion changes (keys the reference cache)


class Unsupported(Exception):
    pass


def load_toml(path):
    with open(path, "rb") as f:
        return tomllib.load(f)


def rgb(value, where):
    if isinstance(value, (int, float)):
        return [float(value)] * 3
    if isinstance(value, list) and len(value) == 3:
        return [float(v) for v in value]
    raise Unsupported(f"{where}: expected a number or [r, g, b], got {value!r}")


def spectrum(value, where):
    return {"type": "rgb", "value": rgb(value, where)}


def check_keys(table, allowed, where):
    extra = set(table) - set(allowed)
    if extra:
        raise Unsupported(f"{where}: key(s) {sorted(extra)} not supported by the Mitsuba converter")


def referenced_files(scene, scene_dir):
    """Every file a scene reads (for the reference cache key)."""
    files = []
    for light in scene.get("light", []):
        if "filename" in light:
            files.append(os.path.join(scene_dir, light["filename"]))
    for shape in scene.get("shape", []):
        if "file" in shape:
            files.append(os.path.join(scene_dir, shape["file"]))
    for bsdf in scene.get("bsdf", []):
        if "file" in bsdf:
            files.append(os.path.join(scene_dir, bsdf["file"]))
    return files


def scene_hash(path, extra=""):
    scene = load_toml(path)
    h = hashlib.sha256()
    # The parsed scene, not its text: an edited comment keeps the reference.
    h.update(json.dumps(scene, sort_keys=True, default=str).encode())
    for f in referenced_files(scene, os.path.dirname(os.path.abspath(path))):
        h.update(os.path.basename(f).encode())
        with open(f, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
    h.update(CONVERTER_VERSION.encode())
    h.update(extra.encode())
    return h.hexdigest()[:16]


# ---------------------------------------------------------------- BSDFs


def isotropic_roughness(b, where, what):
    """The roughness of a model Mitsuba has only isotropic (its smooth and
    rough dielectric and plastic)."""
    r = b.get("roughness", 0.0)
    if b.get("roughness_v", r) != r:
        raise Unsupported(f"{where}: anisotropic {what}")
    return r


def convert_bsdf(b, mi):
    where = f"[[bsdf]] {b.get('name')!r}"
    t = b.get("type")
    if t == "diffuse":
        check_keys(b, ["name", "type", "reflectance", "two_sided", "sampling"], where)
        if b.get("sampling", "cosine") != "cosine":
            raise Unsupported(f"{where}: sampling {b['sampling']!r} (Mitsuba samples the cosine)")
        d = {"type": "diffuse", "reflectance": spectrum(b.get("reflectance", 0.5), where)}
        return {"type": "twosided", "bsdf": d} if b.get("two_sided", False) else d
    if t in ("conductor", "mirror"):
        check_keys(b, ["name", "type", "distribution", "roughness", "roughness_v", "material", "eta", "k",
                       "specular_reflectance", "sampling"], where)
        if b.get("sampling", "visible") != "visible":
            raise Unsupported(f"{where}: sampling {b['sampling']!r} (Mitsuba: visible normals or full D)")
        d = {"specular_reflectance": spectrum(b.get("specular_reflectance", 1.0), where)}
        if "eta" in b or "k" in b:
            if "material" in b:
                raise Unsupported(f"{where}: both material and eta/k")
            d["eta"] = spectrum(b["eta"], where)
            d["k"] = spectrum(b["k"], where)
        else:
            material = b.get("material", "none")
            if material != "none":
                # Mitsuba's tabulated spectra and lumis's RGB presets differ.
                raise Unsupported(f"{where}: material {material!r}: give eta and k explicitly")
            d["material"] = "none"
        au = b.get("roughness", 0.1) if t == "conductor" else 0.0
        av = b.get("roughness_v", au)
        if max(au, av) < 1e-3 or t == "mirror":
            d["type"] = "conductor"
            return d
        d.update(type="roughconductor", distribution=b.get("distribution", "ggx"), sample_visible=True)
        if au == av:
            d["alpha"] = float(au)
        else:
            d["alpha_u"], d["alpha_v"] = float(au), float(av)
        return d
    if t == "dielectric":
        check_keys(b, ["name", "type", "int_ior", "ext_ior", "distribution", "roughness", "roughness_v", "sampling"], where)
        d = {"int_ior": float(b.get("int_ior", 1.5)), "ext_ior": float(b.get("ext_ior", 1.0))}
        r = isotropic_roughness(b, where, "dielectric")
        if r < 1e-3:
            d["type"] = "dielectric"
        else:
            d.update(type="roughdielectric", distribution=b.get("distribution", "ggx"), alpha=float(r),
                     sample_visible=b.get("sampling", "visible") == "visible")
        return d
    if t == "plastic":
        check_keys(b, ["name", "type", "diffuse_reflectance", "specular_reflectance", "int_ior", "ext_ior",
                       "distribution", "roughness", "roughness_v", "nonlinear"], where)
        d = {
            "diffuse_reflectance": spectrum(b.get("diffuse_reflectance", 0.5), where),
            "specular_reflectance": spectrum(b.get("specular_reflectance", 1.0), where),
            "int_ior": float(b.get("int_ior", 1.49)),
            "ext_ior": float(b.get("ext_ior", 1.0)),
            "nonlinear": bool(b.get("nonlinear", False)),
        }
        r = isotropic_roughness(b, where, "plastic")
        if r < 1e-3:
            d["type"] = "plastic"
        else:
            d.update(type="roughplastic", distribution=b.get("distribution", "ggx"), alpha=float(r))
        return d
    if t == "measured":
        raise Unsupported(f"{where}: measured (MERL) BRDFs: Mitsuba 3 has no MERL plugin in its default build")
    raise Unsupported(f"{where}: BSDF type {t!r}")


# ---------------------------------------------------------------- meshes


def make_mesh(mi, name, positions, indices, normals=None, uvs=None, bsdf=None, emitter=None, flip=False):
    """An mi.Mesh from numpy arrays (no file round trip)."""
    props = mi.Properties()
    if bsdf is not None:
        props["bsdf"] = mi.load_dict(bsdf)
    if emitter is not None:
        props["emitter"] = mi.load_dict(emitter)
    if flip:
        props["flip_normals"] = True
    positions = np.ascontiguousarray(positions, np.float32).reshape(-1, 3)
    indices = np.ascontiguousarray(indices, np.uint32).reshape(-1, 3)
    mesh = mi.Mesh(name, len(positions), len(indices), props,
                   has_vertex_normals=normals is not None, has_vertex_texcoords=uvs is not None)
    params = mi.traverse(mesh)
    F, U = type(params["vertex_positions"]), type(params["faces"])
    params["vertex_positions"] = F(positions.ravel())
    params["faces"] = U(indices.ravel())
    if normals is not None:
        params["vertex_normals"] = F(np.ascontiguousarray(normals, np.float32).ravel())
    if uvs is not None:
        params["vertex_texcoords"] = F(np.ascontiguousarray(uvs, np.float32).ravel())
    params.update()
    return mesh


def quat_matrix(q):
    x, y, z, w = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def trs(translate=(0, 0, 0), rotate3=None, scale=(1, 1, 1)):
    m = np.eye(4)
    m[:3, :3] = (rotate3 if rotate3 is not None else np.eye(3)) @ np.diag(scale)
    m[:3, 3] = translate
    return m


def toml_transform(t, where):
    if t is None:
        return np.eye(4)
    check_keys(t, ["matrix", "scale", "rotate", "translate"], where + " transform")
    if "matrix" in t:
        return np.array(t["matrix"], dtype=float).reshape(4, 4)
    rot = None
    if "rotate" in t:
        ax, ay, az, deg = t["rotate"]
        axis = np.array([ax, ay, az], float)
        axis /= np.linalg.norm(axis)
        a = math.radians(deg)
        K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        rot = np.eye(3) + math.sin(a) * K + (1 - math.cos(a)) * K @ K
    return trs(t.get("translate", (0, 0, 0)), rot, t.get("scale", (1, 1, 1)))


class Gltf:
    """The part of glTF 2.0 the bench assets use: .glb or .gltf (data URIs or
    external buffers), float32 POSITION/NORMAL/TEXCOORD_0, u8/u16/u32
    indices, TRIANGLES, node TRS or matrix, metallic-roughness materials with
    a base colour texture."""

    def __init__(self, path):
        self.dir = os.path.dirname(path)
        data = open(path, "rb").read()
        self.bin = None
        if data[:4] == b"glTF":
            _, _, _ = struct.unpack_from("<III", data, 0)
            off = 12
            while off < len(data):
                n, kind = struct.unpack_from("<II", data, off)
                chunk = data[off + 8: off + 8 + n]
                if kind == 0x4E4F534A:
                    self.doc = json.loads(chunk)
                elif kind == 0x004E4942:
                    self.bin = chunk
                off += 8 + n
        else:
            self.doc = json.loads(data)
        for ext in self.doc.get("extensionsUsed", []):
            raise Unsupported(f"{path}: glTF extension {ext}")
        self.buffers = [self._buffer(b) for b in self.doc.get("buffers", [])]
        self.path = path

    def _buffer(self, b):
        uri = b.get("uri")
        if uri is None:
            return self.bin
        if uri.startswith("data:"):
            return base64.b64decode(uri.split(",", 1)[1])
        return open(os.path.join(self.dir, uri), "rb").read()

    def view_bytes(self, i):
        v = self.doc["bufferViews"][i]
        buf = self.buffers[v["buffer"]]
        off = v.get("byteOffset", 0)
        return buf[off: off + v["byteLength"]], v.get("byteStride")

    def accessor(self, i):
        a = self.doc["accessors"][i]
        if "sparse" in a:
            raise Unsupported(f"{self.path}: sparse accessor {i}")
        comps = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[a["type"]]
        dtype = {5121: np.uint8, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}[a["componentType"]]
        data, stride = self.view_bytes(a["bufferView"])
        item = np.dtype(dtype).itemsize * comps
        off = a.get("byteOffset", 0)
        if stride and stride != item:
            raw = np.frombuffer(data, np.uint8)
            rows = np.stack([raw[off + k * stride: off + k * stride + item] for k in range(a["count"])])
            return rows.view(dtype).reshape(a["count"], comps)
        return np.frombuffer(data, dtype, a["count"] * comps, off).reshape(a["count"], comps)

    def image_bytes(self, i):
        img = self.doc["images"][i]
        if "bufferView" in img:
            return self.view_bytes(img["bufferView"])[0]
        uri = img["uri"]
        if uri.startswith("data:"):
            return base64.b64decode(uri.split(",", 1)[1])
        return open(os.path.join(self.dir, uri), "rb").read()

    def node_matrix(self, node):
        if "matrix" in node:
            return np.array(node["matrix"], float).reshape(4, 4).T  # column-major
        rot = quat_matrix(node["rotation"]) if "rotation" in node else None
        return trs(node.get("translation", (0, 0, 0)), rot, node.get("scale", (1, 1, 1)))

    def mesh_nodes(self):
        """(mesh index, world matrix) for every node of the default scene."""
        scene = self.doc["scenes"][self.doc.get("scene", 0)]
        out = []

        def walk(i, parent):
            node = self.doc["nodes"][i]
            for k in ("skin", "weights"):
                if k in node:
                    raise Unsupported(f"{self.path}: node {i} has {k}")
            m = parent @ self.node_matrix(node)
            if "mesh" in node:
                out.append((node["mesh"], m, node.get("name", str(i))))
            for c in node.get("children", []):
                walk(c, m)

        for i in scene["nodes"]:
            walk(i, np.eye(4))
        return out


def gltf_material_bsdf(g, index, tex_dir, mi):
    """lumis's bsdf_table mapping of a glTF material, as Mitsuba BSDFs."""
    where = f"{g.path} material {index}"
    if index is None:
        raise Unsupported(f"{g.path}: a primitive without material (give the shape a `bsdf`)")
    m = g.doc["materials"][index]
    for k in ("emissiveTexture", "normalTexture", "occlusionTexture", "extensions"):
        if k in m:
            raise Unsupported(f"{where}: {k}")
    if any(m.get("emissiveFactor", [0, 0, 0])):
        raise Unsupported(f"{where}: emissive material")
    if m.get("alphaMode", "OPAQUE") != "OPAQUE":
        raise Unsupported(f"{where}: alphaMode {m['alphaMode']}")
    pbr = m.get("pbrMetallicRoughness", {})
    if "metallicRoughnessTexture" in pbr:
        raise Unsupported(f"{where}: metallicRoughnessTexture")
    factor = pbr.get("baseColorFactor", [1, 1, 1, 1])[:3]
    metallic = pbr.get("metallicFactor", 1.0)
    if 0 < metallic < 1:
        raise Unsupported(f"{where}: metallicFactor {metallic} strictly between 0 and 1")
    alpha = pbr.get("roughnessFactor", 1.0) ** 2
    colour = {"type": "rgb", "value": [float(c) for c in factor]}
    if "baseColorTexture" in pbr:
        t = pbr["baseColorTexture"]
        if t.get("texCoord", 0) != 0 or "extensions" in t:
            raise Unsupported(f"{where}: texCoord or texture transform")
        if factor != [1, 1, 1]:
            raise Unsupported(f"{where}: a texture times a baseColorFactor other than 1")
        tex = g.doc["textures"][t["index"]]
        sampler = g.doc.get("samplers", [{}])[tex["sampler"]] if "sampler" in tex else {}
        wrap = {10497: "repeat", 33648: "mirror", 33071: "clamp"}
        ws, wt = sampler.get("wrapS", 10497), sampler.get("wrapT", 10497)
        if ws != wt:
            raise Unsupported(f"{where}: different wrap modes in s and t")
        png = g.image_bytes(tex["source"])
        os.makedirs(tex_dir, exist_ok=True)
        ext = ".png" if png[:4] == b"\x89PNG" else ".jpg"
        fn = os.path.join(tex_dir, hashlib.sha256(png).hexdigest()[:16] + ext)
        if not os.path.exists(fn):
            with open(fn, "wb") as f:
                f.write(png)
        colour = {"type": "bitmap", "filename": fn, "raw": False, "wrap_mode": wrap[ws],
                  "filter_type": "nearest" if sampler.get("magFilter") == 9728 else "bilinear"}
    if metallic >= 0.5:
        d = {"material": "none", "specular_reflectance": colour}
        if alpha < 1e-3:
            d["type"] = "conductor"
        else:
            d.update(type="roughconductor", distribution="ggx", alpha=alpha, sample_visible=True)
    else:
        d = {"diffuse_reflectance": colour, "int_ior": 1.5, "ext_ior": 1.0, "nonlinear": False}
        if alpha < 1e-3:
            d["type"] = "plastic"
        else:
            d.update(type="roughplastic", distribution="ggx", alpha=alpha)
    if m.get("doubleSided", False):
        d = {"type": "twosided", "bsdf": d}
    return d


def gltf_shapes(shape, scene_dir, bsdfs, emitter, tex_dir, mi, prefix):
    where = f"[[shape]] gltf {shape['file']!r}"
    check_keys(shape, ["type", "file", "transform", "bsdf", "bsdf_overrides", "crease_angle", "emission",
                       "flip_normals"], where)
    if emitter is not None:
        raise Unsupported(f"{where}: emission on a glTF shape")
    g = Gltf(os.path.join(scene_dir, shape["file"]))
    top = toml_transform(shape.get("transform"), where)
    overrides = shape.get("bsdf_overrides", {})
    out = {}
    for k, (mesh_i, m, node_name) in enumerate(g.mesh_nodes()):
        m = top @ m
        mesh = g.doc["meshes"][mesh_i]
        for p_i, prim in enumerate(mesh["primitives"]):
            if prim.get("mode", 4) != 4:
                raise Unsupported(f"{where}: primitive mode {prim['mode']}")
            if "targets" in prim:
                raise Unsupported(f"{where}: morph targets")
            attrs = prim["attributes"]
            pos = g.accessor(attrs["POSITION"]).astype(np.float64)
            idx = (g.accessor(prim["indices"]).ravel() if "indices" in prim
                   else np.arange(len(pos))).astype(np.uint32).reshape(-1, 3)
            if "NORMAL" not in attrs:
                if shape.get("crease_angle", 30.0) != 0:
                    raise Unsupported(f"{where}: no NORMAL (lumis would generate them by crease angle)")
                nrm = None
            else:
                nrm = g.accessor(attrs["NORMAL"]).astype(np.float64)
            mat_i = prim.get("material")
            mat_name = g.doc["materials"][mat_i].get("name") if mat_i is not None else None
            if "bsdf" in shape:
                bsdf = bsdfs[shape["bsdf"]]
                uvs = None
            elif mat_name in overrides:
                bsdf = bsdfs[overrides[mat_name]]
                uvs = None
            else:
                bsdf = gltf_material_bsdf(g, mat_i, tex_dir, mi)
                textured = "baseColorTexture" in g.doc["materials"][mat_i].get("pbrMetallicRoughness", {})
                uvs = g.accessor(attrs["TEXCOORD_0"]) if textured else None
            pos = pos @ m[:3, :3].T + m[:3, 3]
            if nrm is not None:
                nrm = nrm @ np.linalg.inv(m[:3, :3])  # inverse transpose, row vectors
                nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-30)
            if np.linalg.det(m[:3, :3]) < 0:
                idx = idx[:, [0, 2, 1]]
            name = f"{prefix}-{k}-{node_name}-{p_i}"
            out[name] = make_mesh(mi, name, pos, idx, nrm, uvs, bsdf, None, shape.get("flip_normals", False))
    return out


# ---------------------------------------------------------------- scene


def obj_has_normals(path):
    with open(path) as f:
        return any(line.startswith("vn ") for line in f)


def convert(path, mi, sampler="independent", spp=64, seed=0, tex_dir=None):
    """The Mitsuba scene dict of the lumis scene at `path`."""
    scene = load_toml(path)
    scene_dir = os.path.dirname(os.path.abspath(path))
    tex_dir = tex_dir or os.path.join(scene_dir, "assets", "textures")
    check_keys(scene, ["seed", "film", "camera", "sampler", "integrator", "light_sampler", "bsdf", "shape",
                       "light", "accel"], path)

    film = scene.get("film", {})
    check_keys(film, ["resolution", "output", "filter"], "[film]")
    if film.get("filter", {"type": "box"}).get("type") != "box":
        raise Unsupported("[film] filter other than box")
    w, h = film.get("resolution", [256, 256])

    cam = scene["camera"]
    if cam.get("type") != "perspective":
        raise Unsupported(f"[camera] type {cam.get('type')!r}")
    check_keys(cam, ["type", "origin", "target", "up", "fov"], "[camera]")
    sensor = {
        "type": "perspective",
        "fov": float(cam["fov"]),
        "fov_axis": "smaller",
        "to_world": mi.ScalarTransform4f().look_at(origin=cam["origin"], target=cam["target"],
                                                   up=cam.get("up", [0, 1, 0])),
        "sampler": {"type": sampler, "sample_count": spp, "seed": seed},
        "film": {"type": "hdrfilm", "width": w, "height": h, "rfilter": {"type": "box"},
                 "pixel_format": "rgb", "component_format": "float32"},
    }

    integ = scene.get("integrator", {"type": "path"})
    if integ.get("type") != "path":
        raise Unsupported(f"[integrator] type {integ.get('type')!r}")
    check_keys(integ, ["type", "max_depth", "rr_depth", "strategy", "heuristic", "beta", "n_f", "n_g",
                       "estimator"], "[integrator]")
    for key, default in (("strategy", "mis"), ("heuristic", "power"), ("beta", 2.0), ("n_f", 1), ("n_g", 1),
                         ("estimator", "multi-sample")):
        if integ.get(key, default) != default:
            raise Unsupported(f"[integrator] {key} = {integ[key]!r} (Mitsuba's path: MIS, power heuristic, 1+1 samples)")
    ls = scene.get("light_sampler", {"type": "uniform"})
    if ls.get("type") not in ("uniform", "bvh"):
        raise Unsupported(f"[light_sampler] type {ls.get('type')!r} (Mitsuba picks emitters uniformly)")

    out = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": int(integ.get("max_depth", 8)),
                       "rr_depth": int(integ.get("rr_depth", 5))},
        "sensor": sensor,
    }
    bsdfs = {b["name"]: convert_bsdf(b, mi) for b in scene.get("bsdf", [])}

    for i, shape in enumerate(scene.get("shape", [])):
        t = shape.get("type")
        where = f"[[shape]] {i} ({t})"
        emitter = None
        if "emission" in shape:
            e = shape["emission"]
            check_keys(e, ["radiance", "two_sided", "sampling", "type"], where + " emission")
            if e.get("two_sided", False):
                raise Unsupported(f"{where}: two-sided emission (Mitsuba's area emitter is one-sided)")
            emitter = {"type": "area", "radiance": spectrum(e["radiance"], where)}
        flip = shape.get("flip_normals", False)
        name = f"shape-{i:03d}"
        if t == "gltf":
            out.update(gltf_shapes(shape, scene_dir, bsdfs, emitter, tex_dir, mi, name))
            continue
        if "bsdf" not in shape:
            raise Unsupported(f"{where}: no bsdf")
        bsdf = bsdfs[shape["bsdf"]]
        if t == "obj":
            check_keys(shape, ["type", "file", "bsdf", "emission", "flip_normals"], where)
            fn = os.path.join(scene_dir, shape["file"])
            d = {"type": "obj", "filename": fn, "face_normals": not obj_has_normals(fn), "bsdf": bsdf}
        elif t == "quad":
            check_keys(shape, ["type", "corner", "edge_u", "edge_v", "bsdf", "emission", "flip_normals"], where)
            c, u, v = (np.array(shape[k], float) for k in ("corner", "edge_u", "edge_v"))
            n = np.cross(u, v)
            n /= np.linalg.norm(n)
            m = np.eye(4)
            m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = u / 2, v / 2, n, c + (u + v) / 2
            d = {"type": "rectangle", "to_world": mi.ScalarTransform4f(m.tolist()), "bsdf": bsdf}
        elif t == "sphere":
            check_keys(shape, ["type", "center", "radius", "bsdf", "emission", "flip_normals"], where)
            d = {"type": "sphere", "center": [float(x) for x in shape["center"]],
                 "radius": float(shape["radius"]), "bsdf": bsdf}
        elif t == "mesh":
            check_keys(shape, ["type", "positions", "indices", "normals", "bsdf", "emission", "flip_normals"], where)
            out[name] = make_mesh(mi, name, shape["positions"], shape["indices"], shape.get("normals"), None,
                                  bsdf, emitter, flip)
            continue
        else:
            raise Unsupported(f"{where}: shape type {t!r}")
        if emitter is not None:
            d["emitter"] = emitter
        if flip:
            d["flip_normals"] = True
        out[name] = d

    for i, light in enumerate(scene.get("light", [])):
        t = light.get("type")
        where = f"[[light]] {i} ({t})"
        if t == "point":
            check_keys(light, ["type", "position", "intensity"], where)
            out[f"light-{i}"] = {"type": "point", "position": [float(x) for x in light["position"]],
                                 "intensity": spectrum(light["intensity"], where)}
        elif t == "constant":
            check_keys(light, ["type", "radiance"], where)
            out[f"light-{i}"] = {"type": "constant", "radiance": spectrum(light["radiance"], where)}
        elif t == "envmap":
            check_keys(light, ["type", "filename", "scale", "up", "rotation", "sampling"], where)
            if light.get("sampling", "importance") != "importance":
                raise Unsupported(f"{where}: sampling {light['sampling']!r} (Mitsuba's envmap samples by luminance)")
            up = np.array([float(x) for x in light.get("up", [0.0, 1.0, 0.0])])
            up /= np.linalg.norm(up)
            # The shortest arc taking +y to up, after `rotation` degrees about +y.
            axis = np.cross([0.0, 1.0, 0.0], up)
            to_world = mi.ScalarTransform4f()
            if np.linalg.norm(axis) > 1e-9:
                angle = math.degrees(math.atan2(np.linalg.norm(axis), up[1]))
                to_world = to_world.rotate([float(a) for a in axis / np.linalg.norm(axis)], angle)
            elif up[1] < 0.0:
                to_world = to_world.rotate([1.0, 0.0, 0.0], 180.0)
            to_world = to_world.rotate([0.0, 1.0, 0.0], float(light.get("rotation", 0.0)))
            out[f"light-{i}"] = {"type": "envmap", "filename": os.path.join(scene_dir, light["filename"]),
                                 "scale": float(light.get("scale", 1.0)), "to_world": to_world}
        else:
            raise Unsupported(f"{where}: light type {t!r}")
    return out
