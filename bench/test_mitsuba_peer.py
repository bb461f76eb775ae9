#!/usr/bin/env python3
"""Tests of bench/mitsuba_peer.py's conversion (no Mitsuba needed; the few that
check Mitsuba's own behaviour run where it is installed, and skip elsewhere):

    python3 -m unittest discover -s bench -p 'test_mitsuba_peer.py' -v
    python3.12 -m unittest discover -s bench -p 'test_mitsuba_peer.py' -v   # with Mitsuba 3.7.1
"""

import array
import json
import math
import os
import shutil
import struct
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "tools"))

import mitsuba_peer as mp  # noqa: E402


def scene_doc(**kw):
    doc = {
        "camera": {"look_from": [0, 5, -20], "look_at": [0, 0.5, 0], "up": [0, 1, 0], "vfov": 20},
        "sky": {"type": "uniform", "radiance": [0, 0, 0]},
        "render": {"width": 64, "height": 32, "spp": 4, "depth": 7, "roulette_depth": 3, "seed": 9},
        "materials": [{"name": "grey", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]}],
        "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "grey"}],
    }
    doc.update(kw)
    return doc


def col(m, c):
    return [m[r][c] for r in range(3)]


def close(a, b, tol=1e-6):
    return all(abs(x - y) <= tol for x, y in zip(a, b))


class Base(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="peer-test-")
        self.old_cache = os.environ.get("WAVETRACE_PEER_CACHE")
        os.environ["WAVETRACE_PEER_CACHE"] = os.path.join(self.tmp, "cache")

    def tearDown(self):
        if self.old_cache is None:
            os.environ.pop("WAVETRACE_PEER_CACHE", None)
        else:
            os.environ["WAVETRACE_PEER_CACHE"] = self.old_cache
        shutil.rmtree(self.tmp)

    def convert(self, doc, **kw):
        path = os.path.join(self.tmp, "scene.json")
        with open(path, "w") as f:
            json.dump(doc, f)
        return mp.convert(path, **kw)

    def shapes(self, conv, kind):
        return [v for v in conv.scene.values() if isinstance(v, dict) and v.get("type") == kind]

    def bsdf_of(self, conv, shape):
        b = shape["bsdf"]
        return conv.scene[b["id"]] if b.get("type") == "ref" else b


class CameraTest(Base):
    def test_perspective_fov_and_axes(self):
        conv = self.convert(scene_doc())
        s = conv.scene["sensor"]
        self.assertEqual(s["type"], "perspective")
        self.assertEqual(s["fov"], 20.0)
        self.assertEqual(s["fov_axis"], "y")
        m = s["to_world"]["__transform__"]
        forward = col(m, 2)
        d = [0, -4.5, 20]
        n = math.sqrt(sum(x * x for x in d))
        self.assertTrue(close(forward, [x / n for x in d]))
        self.assertTrue(close(col(m, 3), [0, 5, -20]))
        # Mitsuba's camera x is "left": up x forward; its y is the image's up.
        self.assertGreater(col(m, 0)[0], 0.99)   # looking along +z, left is +x
        self.assertGreater(col(m, 1)[1], 0.97)
        self.assertAlmostEqual(sum(a * b for a, b in zip(col(m, 1), forward)), 0.0, places=6)
        f = s["film"]
        self.assertEqual((f["width"], f["height"], f["rfilter"]["type"]), (64, 32, "box"))
        self.assertEqual(s["sampler"], {"type": "independent", "sample_count": 4, "seed": 9})

    def test_thin_lens_radius_and_default_focus(self):
        doc = scene_doc()
        doc["camera"]["aperture"] = 0.1
        s = self.convert(doc).scene["sensor"]
        self.assertEqual(s["type"], "thinlens")
        self.assertAlmostEqual(s["aperture_radius"], 0.05)
        self.assertAlmostEqual(s["focus_distance"], math.sqrt(4.5 ** 2 + 20 ** 2), places=5)
        doc["camera"]["focus_distance"] = 7
        s = self.convert(doc).scene["sensor"]
        self.assertEqual(s["focus_distance"], 7.0)

    def test_command_line_overrides(self):
        conv = self.convert(scene_doc(), width=10, height=20, spp=30)
        f = conv.scene["sensor"]["film"]
        self.assertEqual((f["width"], f["height"]), (10, 20))
        self.assertEqual(conv.scene["sensor"]["sampler"]["sample_count"], 30)


class DepthTest(Base):
    def test_depth_and_roulette(self):
        i = self.convert(scene_doc()).scene["integrator"]
        self.assertEqual(i, {"type": "path", "max_depth": 7, "rr_depth": 3, "hide_emitters": False})
        i = self.convert(scene_doc(), depth=30, roulette_depth=30).scene["integrator"]
        self.assertEqual((i["max_depth"], i["rr_depth"]), (30, 30))


class TransformTest(unittest.TestCase):
    def test_order_translate_rotate_scale(self):
        # Scale first, then Rx, Ry, Rz, then the translation.
        m = mp.instance_matrix({"translate": [10, 0, 0], "rotate": [0, 90, 0], "scale": [2, 1, 1]})
        self.assertTrue(close(mp.mat_point(m, [1, 0, 0]), [10, 0, -2]))
        m = mp.instance_matrix({"rotate": [90, 90, 0]})   # x first: (0,1,0) -> (0,0,1) -> (1,0,0)
        self.assertTrue(close(mp.mat_point(m, [0, 1, 0]), [1, 0, 0]))
        m = mp.instance_matrix({"rotate": [0, 0, 90]})
        self.assertTrue(close(mp.mat_point(m, [1, 0, 0]), [0, 1, 0]))
        m = mp.instance_matrix({"scale": 3})
        self.assertTrue(close(mp.mat_point(m, [1, 2, 3]), [3, 6, 9]))

    def test_matrix_is_row_major(self):
        m = mp.instance_matrix({"matrix": [1, 0, 0, 4, 0, 1, 0, 5, 0, 0, 1, 6, 0, 0, 0, 1]})
        self.assertTrue(close(mp.mat_point(m, [0, 0, 0]), [4, 5, 6]))

    def test_inverse(self):
        m = mp.instance_matrix({"translate": [1, 2, 3], "rotate": [10, 20, 30], "scale": [1, 2, 3]})
        p = mp.mat_point(mp.mat_inverse_affine(m), mp.mat_point(m, [0.3, -0.7, 2.0]))
        self.assertTrue(close(p, [0.3, -0.7, 2.0], 1e-9))

    def test_sphere_frame_matches_wavetrace_uv(self):
        # Mitsuba's sphere: u = atan2(l.y, l.x) / 2 pi (in [0, 1)), v = acos(l.z) / pi,
        # l = the unit normal in the sphere's frame; wavetrace's: u = 0.5 + atan2(n.z,
        # n.x) / 2 pi, v = acos(n.y) / pi. to_uv turns Mitsuba's u into 1 - u.
        r = mp.SPHERE_FRAME
        self.assertAlmostEqual(mp.mat_det3(r), 1.0)
        for n in ([0.3, 0.5, -0.81], [-0.6, 0.0, 0.8], [0.1, -0.9, 0.42], [-0.5, 0.5, -0.707]):
            ln = math.sqrt(sum(x * x for x in n))
            n = [x / ln for x in n]
            l = [sum(r[k][i] * n[k] for k in range(3)) for i in range(3)]   # R^T n
            u_mi = (math.atan2(l[1], l[0]) / (2 * math.pi)) % 1.0
            v_mi = math.acos(l[2]) / math.pi
            u_wt = 0.5 + math.atan2(n[2], n[0]) / (2 * math.pi)
            v_wt = math.acos(n[1]) / math.pi
            u_after = mp.SPHERE_TO_UV[0][0] * u_mi + mp.SPHERE_TO_UV[0][3]
            self.assertAlmostEqual(u_after % 1.0, u_wt % 1.0, places=9)
            self.assertAlmostEqual(v_mi, v_wt, places=9)


class MaterialTest(Base):
    MATERIALS = [
        {"name": "matte", "type": "lambertian", "albedo": [0.2, 0.3, 0.4]},
        {"name": "mirror", "type": "metal", "albedo": [0.9, 0.8, 0.7], "fuzz": 0},
        {"name": "brushed", "type": "metal", "albedo": [0.9, 0.8, 0.7], "fuzz": 0.3},
        {"name": "glass", "type": "dielectric", "ior": 1.5},
        {"name": "tinted", "type": "dielectric", "ior": 1.3, "albedo": [0.9, 1, 0.9]},
        {"name": "lacquer", "type": "coated", "albedo": [0.1, 0.3, 0.8], "ior": 1.6},
        {"name": "lamp", "type": "emissive", "emission": [4, 3, 2]},
    ]

    def by_material(self, conv):
        out = {}
        for s in self.shapes(conv, "sphere"):
            out[tuple(s["to_world"]["__transform__"][0][3:])] = s
        return out

    def convert_all(self):
        spheres = [{"center": [3 * k, 0, 0], "radius": 1, "material": m["name"]} for k, m in enumerate(self.MATERIALS)]
        return self.convert(scene_doc(materials=self.MATERIALS, spheres=spheres))

    def test_kinds(self):
        conv = self.convert_all()
        shapes = self.shapes(conv, "sphere")
        self.assertEqual(len(shapes), len(self.MATERIALS))
        b = [self.bsdf_of(conv, s) for s in shapes]
        self.assertEqual(b[0], {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.2, 0.3, 0.4]}})
        self.assertEqual(b[1]["type"], "conductor")
        self.assertEqual(b[1]["material"], "none")
        self.assertEqual(b[1]["specular_reflectance"]["value"], [0.9, 0.8, 0.7])
        self.assertEqual(b[2]["type"], "roughconductor")
        self.assertEqual(b[2]["distribution"], "beckmann")
        self.assertAlmostEqual(b[2]["alpha"], 0.3 / math.sqrt(6))
        self.assertEqual((b[3]["type"], b[3]["int_ior"], b[3]["ext_ior"]), ("dielectric", 1.5, 1.0))
        self.assertNotIn("specular_transmittance", b[3])
        self.assertEqual(b[4]["specular_transmittance"]["value"], [0.9, 1.0, 0.9])
        self.assertEqual(b[4]["specular_reflectance"]["value"], [0.9, 1.0, 0.9])
        self.assertEqual((b[5]["type"], b[5]["int_ior"], b[5]["ext_ior"], b[5]["nonlinear"]),
                         ("plastic", 1.6, 1.0, False))
        self.assertEqual(b[5]["diffuse_reflectance"]["value"], [0.1, 0.3, 0.8])
        # An emitter: radiance on the shape, and a black mirror that ends the path.
        self.assertEqual(shapes[6]["emitter"]["type"], "area")
        self.assertEqual(shapes[6]["emitter"]["radiance"]["value"], [4.0, 3.0, 2.0])
        self.assertEqual(b[6]["specular_reflectance"]["value"], [0, 0, 0])
        for s in shapes[:6]:
            self.assertNotIn("emitter", s)

    def test_materials_are_shared(self):
        doc = scene_doc(spheres=[{"center": [k, 0, 0], "radius": 0.2, "material": "grey"} for k in range(5)])
        conv = self.convert(doc)
        ids = {s["bsdf"]["id"] for s in self.shapes(conv, "sphere")}
        self.assertEqual(len(ids), 1)

    def test_sphere_transform(self):
        conv = self.convert(scene_doc(spheres=[{"center": [1, 2, 3], "radius": 2, "material": "grey"}]))
        m = self.shapes(conv, "sphere")[0]["to_world"]["__transform__"]
        self.assertTrue(close(mp.mat_point(m, [0, 0, 0]), [1, 2, 3]))
        self.assertTrue(close(mp.mat_point(m, [0, 0, 1]), [1, 4, 3]))   # the sphere's pole is +y
        self.assertAlmostEqual(abs(mp.mat_det3(m)), 8.0)

    def test_textures(self):
        textures = [
            {"name": "tiles", "type": "checker", "size": 4, "even": [0.9, 0.9, 0.9], "odd": [0.1, 0.2, 0.3]},
            {"name": "veins", "type": "noise", "scale": 4, "high": [1, 1, 1], "low": [0.2, 0.4, 0.6]},
            {"name": "planet", "type": "image", "file": os.path.join(ROOT, "scenes/textures/planet.png"),
             "colorspace": "linear"},
            {"name": "planet_srgb", "type": "image", "file": os.path.join(ROOT, "scenes/textures/planet.png")},
        ]
        materials = [
            {"name": "floor", "type": "lambertian", "albedo": [0.5, 1, 1], "texture": "tiles"},
            {"name": "marble", "type": "lambertian", "albedo": [1, 1, 1], "texture": "veins"},
            {"name": "globe", "type": "lambertian", "texture": "planet"},
            {"name": "tinted_globe", "type": "coated", "albedo": [0.5, 0.5, 0.5], "ior": 1.5, "texture": "planet_srgb"},
        ]
        spheres = [{"center": [5, -7, 2], "radius": 1, "material": "floor"},
                   {"center": [0, 0, 0], "radius": 1, "material": "marble"},
                   {"center": [0, 3, 0], "radius": 1, "material": "globe"},
                   {"center": [0, 6, 0], "radius": 1, "material": "tinted_globe"}]
        conv = self.convert(scene_doc(textures=textures, materials=materials, spheres=spheres))
        shapes = self.shapes(conv, "sphere")
        checker = self.bsdf_of(conv, shapes[0])["reflectance"]
        self.assertEqual(checker["type"], "wt_checker")
        self.assertEqual(checker["size"], 4.0)
        # albedo x texture colours, and object space = p - centre (x and z rows).
        self.assertEqual([checker["even_r"], checker["even_g"], checker["odd_r"], checker["odd_b"]],
                         [0.45, 0.9, 0.05, 0.3])
        self.assertEqual([checker["ox%d" % k] for k in range(4)], [1.0, 0.0, 0.0, -5.0])
        self.assertEqual([checker["oz%d" % k] for k in range(4)], [0.0, 0.0, 1.0, -2.0])
        self.assertIn("wt_checker", conv.python_plugins)
        marble = self.bsdf_of(conv, shapes[1])["reflectance"]
        self.assertEqual(marble, {"type": "rgb", "value": [0.6, 0.7, 0.8]})
        self.assertTrue(any("noise texture 'veins'" in n and "mean colour" in n for n in conv.notes))
        globe = self.bsdf_of(conv, shapes[2])["reflectance"]
        self.assertEqual((globe["type"], globe["raw"], globe["filter_type"]), ("bitmap", True, "bilinear"))
        self.assertEqual(globe["to_uv"]["__transform__"], mp.SPHERE_TO_UV)
        tinted = self.bsdf_of(conv, shapes[3])["diffuse_reflectance"]
        self.assertEqual((tinted["type"], tinted["r"]), ("wt_scale", 0.5))
        self.assertEqual(tinted["texture"]["raw"], False)


class SkyTest(Base):
    def test_black_uniform_sky_is_no_emitter(self):
        conv = self.convert(scene_doc())
        self.assertNotIn("sky", conv.scene)
        self.assertNotIn("null_emitter", conv.scene)

    def test_uniform_sky(self):
        conv = self.convert(scene_doc(sky={"type": "uniform", "radiance": [0.5, 0.5, 0.5]}))
        self.assertEqual(conv.scene["sky"]["type"], "constant")
        self.assertNotIn("sampling_weight", conv.scene["sky"])   # the only emitter: Mitsuba's default

    def test_gradient_sky_image_and_sampling(self):
        conv = self.convert(scene_doc(sky={"type": "gradient", "horizon": [1, 1, 1], "zenith": [0.5, 0.7, 1]}))
        sky = conv.scene["sky"]
        self.assertEqual(sky["type"], "envmap")
        self.assertEqual(sky["sampling_weight"], 0.0)            # wavetrace does not sample it
        self.assertEqual(conv.scene["null_emitter"]["type"], "wt_null")
        with open(sky["filename"], "rb") as f:
            data = f.read()
        head, dims, scale, body = data.split(b"\n", 3)
        w, h = map(int, dims.split())
        self.assertEqual((head, w, h, float(scale)), (b"PF", mp.GRADIENT_SKY_COLUMNS, mp.GRADIENT_SKY_ROWS, -1.0))
        px = array.array("f")
        px.frombytes(body)
        top = px[3 * w * (h - 1):3 * w * (h - 1) + 3]           # PFM: last row stored is the top
        bottom = px[0:3]
        middle = px[3 * w * (h // 2):3 * w * (h // 2) + 3]
        self.assertTrue(close(top, [0.5, 0.7, 1.0]))
        self.assertTrue(close(bottom, [1, 1, 1]))
        self.assertTrue(close(middle, [0.75, 0.85, 1.0], 1e-6))   # dir.y = 0: t = 0.5
        self.assertTrue(any("gradient sky" in n for n in conv.notes))
        conv = self.convert(scene_doc(sky={"type": "gradient"}), sky_sampling="always")
        self.assertNotIn("null_emitter", conv.scene)

    def test_environment_rotation(self):
        sky = {"type": "environment", "file": os.path.join(ROOT, "scenes/textures/sky_sun.hdr"), "rotation": 90,
               "intensity": 2}
        conv = self.convert(scene_doc(sky=sky))
        env = conv.scene["sky"]
        self.assertEqual((env["type"], env["scale"]), ("envmap", 2.0))
        m = env["to_world"]["__transform__"]
        # wavetrace turns the environment about +y, x toward -z.
        self.assertTrue(close(mp.mat_point(m, [1, 0, 0]), [0, 0, -1]))
        self.assertTrue(env["filename"].endswith("sky_sun.hdr"))

    def test_mirror_ball_is_resampled_when_loaded(self):
        sky = {"type": "environment", "file": os.path.join(ROOT, "scenes/textures/probe_beach.png"),
               "mapping": "mirror_ball"}
        conv = self.convert(scene_doc(sky=sky))
        spec = conv.scene["sky"]["__envmap_image__"]
        self.assertEqual((spec["mapping"], spec["srgb"]), ("mirror_ball", True))
        self.assertTrue(any("mirror_ball" in n for n in conv.notes))

    def test_environment_uv_matches_sky_hpp(self):
        self.assertTrue(close(mp.environment_uv("latlong", (0, 0, -1)), (0.0, 0.5)))
        self.assertTrue(close(mp.environment_uv("latlong", (1, 0, 0)), (0.25, 0.5)))
        self.assertTrue(close(mp.environment_uv("latlong", (0, 1, 0)), (0.0, 0.0)))
        self.assertTrue(close(mp.environment_uv("mirror_ball", (0, 0, 1)), (0.5, 0.5)))
        self.assertTrue(close(mp.environment_uv("angular", (0, 0, -1)), (0.5, 0.5)))


class NoPythonPluginsTest(Base):
    def test_fallbacks_are_noted(self):
        textures = [{"name": "tiles", "type": "checker", "size": 1, "even": [1, 1, 1], "odd": [0, 0.5, 0]},
                    {"name": "planet", "type": "image", "file": os.path.join(ROOT, "scenes/textures/planet.png")}]
        materials = [{"name": "floor", "type": "lambertian", "texture": "tiles"},
                     {"name": "globe", "type": "lambertian", "albedo": [0.5, 0.5, 0.5], "texture": "planet"}]
        spheres = [{"center": [0, 0, 0], "radius": 1, "material": "floor"},
                   {"center": [0, 3, 0], "radius": 1, "material": "globe"}]
        conv = self.convert(scene_doc(textures=textures, materials=materials, spheres=spheres,
                                      sky={"type": "gradient"}), python_plugins=False)
        self.assertEqual(conv.python_plugins, [])
        shapes = self.shapes(conv, "sphere")
        self.assertEqual(self.bsdf_of(conv, shapes[0])["reflectance"]["value"], [0.5, 0.75, 0.5])
        self.assertEqual(self.bsdf_of(conv, shapes[1])["reflectance"]["type"], "bitmap")
        self.assertNotIn("null_emitter", conv.scene)
        self.assertNotIn("sampling_weight", conv.scene["sky"])
        notes = " ".join(conv.notes)
        for fragment in ("checker texture 'tiles'", "albedo [0.5, 0.5, 0.5]", "every emitter is sampled"):
            self.assertIn(fragment, notes)
        self.assertNotIn("not sampled as a light", notes)


class LightTest(Base):
    def test_light_picking_weights_follow_power(self):
        materials = [{"name": "a", "type": "emissive", "emission": [3, 3, 3]},
                     {"name": "b", "type": "emissive", "emission": [1, 2, 3]},
                     {"name": "grey", "type": "lambertian"}]
        spheres = [{"center": [0, 0, 0], "radius": 1, "material": "a"},
                   {"center": [5, 0, 0], "radius": 2, "material": "b"},
                   {"center": [0, -100, 0], "radius": 99, "material": "grey"}]
        conv = self.convert(scene_doc(materials=materials, spheres=spheres,
                                      sky={"type": "gradient"}))
        em = [s["emitter"] for s in self.shapes(conv, "sphere") if "emitter" in s]
        self.assertAlmostEqual(em[0]["sampling_weight"], 3 * 4 * math.pi, places=4)
        self.assertAlmostEqual(em[1]["sampling_weight"], 2 * 16 * math.pi, places=4)
        self.assertEqual(conv.scene["sky"]["sampling_weight"], 0.0)
        self.assertNotIn("null_emitter", conv.scene)

    def test_no_nee(self):
        materials = [{"name": "a", "type": "emissive", "emission": [3, 3, 3]}]
        conv = self.convert(scene_doc(materials=materials,
                                      spheres=[{"center": [0, 0, 0], "radius": 1, "material": "a"}]), nee=0)
        em = self.shapes(conv, "sphere")[0]["emitter"]
        self.assertEqual(em["sampling_weight"], 0.0)
        self.assertIn("null_emitter", conv.scene)
        self.assertTrue(any("nee 0" in n for n in conv.notes))


OBJ = """mtllib two.mtl
v 0 0 0
v 1 0 0
v 1 0 1
v 0 0 1
v 0 1 0
v 1 1 0
usemtl red
f 1 2 3 4
usemtl lamp
f 1 5 6
"""
MTL = """newmtl red
Kd 0.65 0.05 0.05
newmtl lamp
Kd 0.5 0.5 0.5
Ke 10 8 6
"""


class MeshTest(Base):
    def write(self, name, text):
        with open(os.path.join(self.tmp, name), "w") as f:
            f.write(text)

    def test_obj_split_by_material_and_placed(self):
        self.write("two.obj", OBJ)
        self.write("two.mtl", MTL)
        materials = [{"name": "bulb", "type": "emissive", "emission": [1, 1, 1]}]
        doc = scene_doc(materials=materials, spheres=[{"center": [0, 9, 0], "radius": 1, "material": "bulb"}],
                        meshes=[{"name": "two", "file": "two.obj"}],
                        instances=[{"mesh": "two", "translate": [0, 0, 5], "scale": 2}])
        conv = self.convert(doc)
        objs = self.shapes(conv, "obj")
        self.assertEqual(len(objs), 2)
        for s in objs:
            self.assertTrue(s["face_normals"])                       # no vn: geometric normals
            self.assertTrue(close(mp.mat_point(s["to_world"]["__transform__"], [1, 1, 1]), [2, 2, 7]))
        red, lamp = objs
        with open(red["filename"]) as f:
            text = f.read()
        self.assertEqual(text.count("\nv "), 4)
        self.assertIn("f 1 2 3 4", text)
        b = self.bsdf_of(conv, red)
        self.assertEqual(b["type"], "twosided")                      # triangles are shaded on both sides
        self.assertEqual(b["bsdf"]["reflectance"]["value"], [0.65, 0.05, 0.05])
        # The lamp: an emitter weighed by its world area (a right triangle of legs 2 x 2).
        self.assertAlmostEqual(lamp["emitter"]["sampling_weight"], 8 * 2.0, places=5)
        self.assertNotIn("emitter", red)
        bulb = self.shapes(conv, "sphere")[0]["emitter"]
        self.assertAlmostEqual(bulb["sampling_weight"], 4 * math.pi, places=5)
        self.assertTrue(any("front side only" in n for n in conv.notes))

    def test_obj_of_one_material_is_used_as_it_is(self):
        self.write("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 0 1\nvn 0 1 0\nvn 0 1 0\nvn 0 1 0\nf 1//1 2//2 3//3\n")
        doc = scene_doc(spheres=[], meshes=[{"name": "quad", "file": "quad.obj"}],
                        instances=[{"mesh": "quad"}], materials=[{"name": "grey", "type": "lambertian"}])
        conv = self.convert(doc)
        s = self.shapes(conv, "obj")[0]
        self.assertEqual(s["filename"], os.path.join(self.tmp, "quad.obj"))
        self.assertNotIn("face_normals", s)
        self.assertNotIn("to_world", s)                              # an identity placement
        self.assertEqual(self.bsdf_of(conv, s)["bsdf"]["reflectance"]["value"], [1, 1, 1])

    def glb(self):
        import meshfile
        positions = array.array("f", [0, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 1])
        normals = array.array("f", [0, 1, 0] * 4)
        uvs = array.array("f", [0, 0, 1, 0, 0, 1, 1, 1])
        indices = array.array("I", [0, 2, 1, 1, 2, 3])
        part = meshfile.Part(positions, normals, uvs, indices, meshfile.pbr_material("stone", (0.4, 0.5, 0.6)))
        meshfile.write_glb(os.path.join(self.tmp, "m.glb"), [part])

    def test_glb_to_ply_and_instances(self):
        self.glb()
        doc = scene_doc(spheres=[], meshes=[{"name": "m", "file": "m.glb"}],
                        instances=[{"mesh": "m", "translate": [k, 0, 0]} for k in range(3)] +
                                  [{"mesh": "m", "material": "grey"}])
        conv = self.convert(doc)
        plys = self.shapes(conv, "ply")
        self.assertEqual(len(plys), 4)                               # flattened by default
        self.assertTrue(any("Mitsuba 3 has no glTF loader" in n for n in conv.notes))
        self.assertTrue(any("each placement is a Mitsuba shape" in n for n in conv.notes))
        with open(plys[0]["filename"], "rb") as f:
            data = f.read()
        head, body = data.split(b"end_header\n", 1)
        self.assertIn(b"element vertex 4", head)
        self.assertIn(b"property float nx", head)
        self.assertIn(b"element face 2", head)
        self.assertEqual(len(body), 4 * 8 * 4 + 2 * 16)
        vx = struct.unpack_from("<8f", body, 8 * 4 * 3)              # the fourth vertex
        self.assertEqual(vx, (1, 0, 1, 0, 1, 0, 1, 1))
        faces = struct.unpack_from("<8I", body, 4 * 8 * 4)
        self.assertEqual(faces, (3, 0, 2, 1, 3, 1, 2, 3))
        self.assertNotIn("face_normals", plys[0])
        # glTF materials are principled (one-sided: doubleSided defaults to false).
        b = self.bsdf_of(conv, plys[0])
        self.assertEqual(b["type"], "principled")
        self.assertTrue(close(b["base_color"]["value"], [0.4, 0.5, 0.6]))
        self.assertEqual(self.bsdf_of(conv, plys[3])["bsdf"]["reflectance"]["value"], [0.5, 0.5, 0.5])
        conv = self.convert(doc, instancing=True)
        groups = self.shapes(conv, "shapegroup")
        inst = self.shapes(conv, "instance")
        self.assertEqual((len(groups), len(inst), len(self.shapes(conv, "ply"))), (1, 3, 1))
        self.assertTrue(close(mp.mat_point(inst[2]["to_world"]["__transform__"], [0, 0, 0]), [2, 0, 0]))


# A few bytes that begin as a PNG does: the converter copies images, never decodes them.
FAKE_PNG = b"\x89PNG\r\n\x1a\n" + bytes(range(40))
FAKE_JPEG = b"\xff\xd8\xff\xe0" + bytes(range(30, 70))


def write_gltf_glb(path, doc, blobs):
    """A GLB of DOC whose buffer 0 is BLOBS (bytes each) one after another, 4-byte
    aligned, each a buffer view (returned in order as view indices)."""
    body, views = b"", []
    for blob in blobs:
        views.append({"buffer": 0, "byteOffset": len(body), "byteLength": len(blob)})
        body += blob + b"\0" * ((-len(blob)) % 4)
    doc = dict(doc, buffers=[{"byteLength": len(body)}], bufferViews=doc.get("bufferViews", []) + views)
    js = json.dumps(doc).encode()
    js += b" " * ((-len(js)) % 4)
    with open(path, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(js) + 8 + len(body)))
        f.write(struct.pack("<II", len(js), 0x4E4F534A) + js)
        f.write(struct.pack("<II", len(body), 0x004E4942) + body)


def quad_doc(materials, images, textures, samplers=(), nodes=None, lights=None, extra_views=0):
    """A glTF of one quad (y = 0, facing +y) per material, its geometry in views
    0-3 (the blobs of QUAD_BLOBS), and the given images / textures / samplers."""
    prims = [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": k}
             for k in range(len(materials))]
    doc = {"asset": {"version": "2.0"}, "scene": 0,
           "scenes": [{"nodes": list(range(len(nodes) if nodes else 1))}],
           "nodes": nodes or [{"mesh": 0}], "meshes": [{"primitives": prims}], "materials": materials,
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
                         {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
                         {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
                         {"bufferView": 3, "componentType": 5125, "count": 6, "type": "SCALAR"}],
           "images": images, "textures": textures, "samplers": list(samplers)}
    if lights:
        doc["extensions"] = {"KHR_lights_punctual": {"lights": lights}}
    return doc


QUAD_BLOBS = [array.array("f", [-0.5, 0, 0.5, 0.5, 0, 0.5, 0.5, 0, -0.5, -0.5, 0, -0.5]).tobytes(),
              array.array("f", [0, 1, 0] * 4).tobytes(),
              array.array("f", [0, 0, 1, 0, 1, 1, 0, 1]).tobytes(),
              array.array("I", [0, 1, 2, 0, 2, 3]).tobytes()]


class GltfPrincipledTest(Base):
    """glTF materials as wavetrace reads them (mesh_load.cpp, map_gltf) on Mitsuba's
    principled and its wrappers."""

    def scene(self, glb_doc, blobs=(), instances=None, **kw):
        write_gltf_glb(os.path.join(self.tmp, "t.glb"), glb_doc, QUAD_BLOBS + list(blobs))
        doc = scene_doc(spheres=[], meshes=[{"name": "t", "file": "t.glb"}],
                        instances=instances or [{"mesh": "t"}], **kw)
        return self.convert(doc)

    def test_principled_factors_textures_wrappers_and_emitter(self):
        # Images: 0 in the GLB's buffer (view 4), 1 a data URI.
        images = [{"bufferView": 4, "mimeType": "image/png"},
                  {"uri": "data:image/jpeg;base64," + __import__("base64").b64encode(FAKE_JPEG).decode()}]
        textures = [{"source": 0, "sampler": 0}, {"source": 1}]
        samplers = [{"wrapS": 33071, "wrapT": 33071, "magFilter": 9729, "minFilter": 9729}]
        transform = {"KHR_texture_transform": {"offset": [0.25, 0.5], "scale": [2, 3], "rotation": 0.5}}
        leaf = {"name": "leaf", "doubleSided": True, "alphaMode": "MASK", "alphaCutoff": 0.3,
                "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.6, 0.7, 0.9], "metallicFactor": 0.25,
                                         "roughnessFactor": 0.5,
                                         "baseColorTexture": {"index": 0, "extensions": transform},
                                         "metallicRoughnessTexture": {"index": 1}},
                "normalTexture": {"index": 1, "scale": 0.5},
                "emissiveFactor": [1, 0.5, 0.25],
                "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4},
                               "KHR_materials_ior": {"ior": 1.4}}}
        conv = self.scene(quad_doc([leaf], images, textures, samplers), [FAKE_PNG],
                          instances=[{"mesh": "t", "translate": [0, 0, 3]}])
        shape = self.shapes(conv, "ply")[0]
        mask = self.bsdf_of(conv, shape)
        self.assertEqual(mask["type"], "mask")                            # alpha outermost
        opacity = mask["opacity"]
        self.assertEqual((opacity["type"], opacity["channel"], opacity["scale"], opacity["cutoff"]),
                         ("wt_channel", 0, 0.9, 0.3))
        self.assertEqual(opacity["texture"]["filename"]["__alpha_image__"]["file"],
                         self.bsdf_of(conv, shape)["bsdf"]["bsdf"]["bsdf"]["base_color"]["texture"]["filename"])
        nm = mask["bsdf"]
        self.assertEqual((nm["type"], nm["normalmap"]["type"], nm["normalmap"]["strength"]),
                         ("normalmap", "wt_normal_scale", 0.5))
        self.assertFalse(nm["normalmap"]["texture"]["raw"] is False)
        two = nm["bsdf"]
        self.assertEqual(two["type"], "twosided")                         # doubleSided true
        b = two["bsdf"]
        self.assertEqual(b["type"], "principled")
        rough = b["roughness"]                                             # green x factor, linear
        self.assertEqual((rough["type"], rough["scale"], rough["power"]), ("wt_roughness", 0.5, 1.0))
        self.assertEqual((b["metallic"]["type"], b["metallic"]["channel"], b["metallic"]["scale"]),
                         ("wt_channel", 2, 0.25))                          # metallic: blue
        self.assertAlmostEqual(b["eta"], 1.4, places=9)                   # f0 of the index itself (s = 1)
        base = b["base_color"]
        self.assertEqual((base["type"], base["r"], base["g"], base["b"]), ("wt_scale", 0.5, 0.6, 0.7))
        bitmap = base["texture"]
        self.assertEqual((bitmap["raw"], bitmap["wrap_mode"], bitmap["filter_type"]), (False, "clamp", "bilinear"))
        c, s_ = math.cos(0.5), math.sin(0.5)
        self.assertTrue(all(close(r1, r2, 1e-12) for r1, r2 in zip(bitmap["to_uv"]["__transform__"], [
            [2 * c, 3 * s_, 0, 0.25], [-2 * s_, 3 * c, 0, 0.5], [0, 0, 1, 0], [0, 0, 0, 1]])))
        # The emitter: emissiveFactor x strength, times the (sRGB) emissive texture where there is one.
        em = shape["emitter"]
        self.assertEqual(em["type"], "area")
        self.assertEqual(em["radiance"]["value"], [4.0, 2.0, 1.0])
        self.assertEqual(conv.scene["integrator"]["type"], "volpath")
        self.assertIn("mask", conv.plugins())

    def test_embedded_images_are_extracted_with_their_bytes(self):
        images = [{"bufferView": 4, "mimeType": "image/png"},
                  {"uri": "data:image/jpeg;base64," + __import__("base64").b64encode(FAKE_JPEG).decode()}]
        textures = [{"source": 0}, {"source": 1}]
        mats = [{"name": "a", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}},
                {"name": "b", "pbrMetallicRoughness": {"baseColorTexture": {"index": 1}}}]
        conv = self.scene(quad_doc(mats, images, textures), [FAKE_PNG])
        files = [self.bsdf_of(conv, s)["base_color"]["filename"] for s in self.shapes(conv, "ply")]
        self.assertEqual([os.path.splitext(f)[1] for f in files], [".png", ".jpg"])
        for f, data in zip(files, (FAKE_PNG, FAKE_JPEG)):
            self.assertEqual(os.path.dirname(f), mp.cache_dir())
            with open(f, "rb") as fh:
                self.assertEqual(fh.read(), data)

    def test_one_sided_specular_and_blend(self):
        mats = [{"name": "plain", "pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.5, 0.9, 0.5],
                                                           "metallicFactor": 0, "roughnessFactor": 0.5},
                 "alphaMode": "BLEND", "extensions": {"KHR_materials_specular": {"specularFactor": 0.5}}}]
        conv = self.scene(quad_doc(mats, [], []))
        mask = self.bsdf_of(conv, self.shapes(conv, "ply")[0])
        self.assertEqual((mask["type"], mask["opacity"]), ("mask", 0.5))   # a constant BLEND alpha
        b = mask["bsdf"]
        self.assertEqual(b["type"], "principled")                         # one-sided: bare (a black back)
        self.assertNotIn("metallic", b)
        r = math.sqrt(0.5 * 0.04)                                          # the index whose f0 is s f0
        self.assertAlmostEqual(b["eta"], (1 + r) / (1 - r), places=9)
        self.assertTrue(any("specular 0.5 -> eta" in n for n in conv.notes))

    def test_clearcoat_transmission_volume(self):
        mats = [{"name": "coat", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.1, 0.1, 1], "metallicFactor": 0},
                 "extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 0.5, "clearcoatRoughnessFactor": 0.2}}},
                {"name": "thin", "pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0.3},
                 "extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.75},
                                "KHR_materials_ior": {"ior": 1.33}}},
                {"name": "volume", "pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0},
                 "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                                "KHR_materials_volume": {"thicknessFactor": 0.3, "attenuationDistance": 0.2,
                                                         "attenuationColor": [0.9, 0.3, 0.2]}}}]
        conv = self.scene(quad_doc(mats, [], []))
        coat, thin, volume = self.shapes(conv, "ply")
        b = self.bsdf_of(conv, coat)
        self.assertEqual(b["type"], "principled")                         # one-sided
        self.assertAlmostEqual(b["clearcoat"], 2.0)                       # 4 c: Mitsuba scales its coat by 0.25
        self.assertAlmostEqual(b["clearcoat_gloss"], (0.1 - 0.04) / 0.099)  # GTR1 alpha = r^2
        b = self.bsdf_of(conv, thin)
        self.assertEqual((b["type"], b["spec_trans"], b["eta"], b["roughness"]), ("principledthin", 0.75, 1.33, 0.3))
        b = self.bsdf_of(conv, volume)
        self.assertEqual((b["type"], b["spec_trans"], b["eta"]), ("principled", 1.0, 1.5))   # refracts: not twosided
        medium = volume["interior"]
        self.assertEqual((medium["type"], medium["albedo"]), ("homogeneous", 0.0))
        self.assertTrue(close(medium["sigma_t"]["value"]["value"], [-math.log(c) / 0.2 for c in (0.9, 0.3, 0.2)]))
        self.assertNotIn("interior", coat)
        self.assertEqual(conv.scene["integrator"]["type"], "volpath")
        notes = " ".join(conv.notes)
        for fragment in ("clearcoat = 4 c", "GTR1", "principledthin", "sqrt(base colour)", "homogeneous medium"):
            self.assertIn(fragment, notes)

    def test_punctual_lights_are_placed_by_node_and_instance(self):
        half = math.radians(-90) / 2                                       # -z turned to -y
        down = [math.sin(half), 0, 0, math.cos(half)]
        lights = [{"type": "point", "intensity": 10, "color": [1, 0.5, 0.25]},
                  {"type": "spot", "intensity": 20, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.4},
                   "range": 5},
                  {"type": "directional", "intensity": 2}]
        nodes = [{"mesh": 0},
                 {"translation": [0, 0.5, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
                 {"translation": [0.3, 0.6, 0], "rotation": down, "extensions": {"KHR_lights_punctual": {"light": 1}}},
                 {"rotation": down, "extensions": {"KHR_lights_punctual": {"light": 2}}}]
        mats = [{"name": "grey", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}}]
        conv = self.scene(quad_doc(mats, [], [], nodes=nodes, lights=lights),
                          instances=[{"mesh": "t", "translate": [1, 0, 2]}, {"mesh": "t", "translate": [-1, 0, 0]}])
        points, spots, suns = (self.shapes(conv, k) for k in ("point", "spot", "directional"))
        self.assertEqual((len(points), len(spots), len(suns)), (2, 2, 2))   # each instance's
        self.assertTrue(close(points[0]["position"], [1, 0.5, 2]))
        self.assertTrue(close(points[1]["position"], [-1, 0.5, 0]))
        self.assertEqual(points[0]["intensity"]["value"], [10, 5, 2.5])   # candela = W/sr
        self.assertAlmostEqual(points[0]["sampling_weight"], 4 * 17.5 / 3, places=4)
        spot = spots[0]
        self.assertEqual(spot["intensity"]["value"], [20, 20, 20])
        self.assertAlmostEqual(spot["cutoff_angle"], math.degrees(0.4))
        self.assertAlmostEqual(spot["beam_width"], math.degrees(0.2))
        m = spot["to_world"]["__transform__"]
        self.assertTrue(close(col(m, 3), [1.3, 0.6, 2]))                  # at the node's origin, placed
        self.assertTrue(close(col(m, 2), [0, -1, 0]))                     # shining down its -z: down
        self.assertAlmostEqual(spot["sampling_weight"], 2 * (1 - math.cos(0.4)) * 20, places=4)
        self.assertTrue(close(suns[0]["direction"], [0, -1, 0]))
        self.assertEqual(suns[0]["irradiance"]["value"], [2, 2, 2])       # lux = W/m^2
        self.assertGreater(suns[0]["sampling_weight"], 0)
        notes = " ".join(conv.notes)
        self.assertIn("range 5", notes)
        self.assertIn("linearly in the angle", notes)
        # nee 0: area lights go unsampled; punctual ones are reached by light sampling alone.
        conv = mp.convert(os.path.join(self.tmp, "scene.json"), nee=0)
        self.assertGreater(self.shapes(conv, "point")[0]["sampling_weight"], 0)

    def test_scene_file_principled(self):
        materials = [{"name": "p", "type": "principled", "albedo": [0.3, 0.4, 0.5], "metallic": 0.5,
                      "roughness": 0.4, "anisotropy": 0.5, "emission": [2, 2, 2]}]
        conv = self.convert(scene_doc(materials=materials, spheres=[{"center": [0, 0, 0], "radius": 1,
                                                                    "material": "p"}]))
        sphere = self.shapes(conv, "sphere")[0]
        b = self.bsdf_of(conv, sphere)
        self.assertEqual(b["type"], "twosided")                           # scene files default to two-sided
        self.assertEqual((b["bsdf"]["metallic"], b["bsdf"]["anisotropic"]), (0.5, 0.5))
        self.assertEqual(sphere["emitter"]["radiance"]["value"], [2.0, 2.0, 2.0])


class TileRegionsTest(Base):
    def test_two_tiles_land_where_the_camera_projects_them(self):
        write_gltf_glb(os.path.join(self.tmp, "t.glb"),
                       quad_doc([{"name": "grey"}], [], []), QUAD_BLOBS)
        cam = {"look_from": [0, 3, 4], "look_at": [0, 0.3, 0], "up": [0, 1, 0], "vfov": 45}
        doc = scene_doc(camera=cam, spheres=[], meshes=[{"name": "t", "file": "t.glb"}],
                        instances=[{"mesh": "t", "translate": [-1, 0, 0]}, {"mesh": "t", "translate": [1, 0, 1]}])
        path = os.path.join(self.tmp, "tiles.json")
        with open(path, "w") as f:
            json.dump(doc, f)
        regions = mp.tile_regions(path, 320, 180)
        self.assertEqual((regions["width"], regions["height"]), (320, 180))
        a, b = regions["tiles"]
        import make_materials as mm
        proj = mm.Projection(cam, 320, 180)
        for tile, centre in ((a, [-1, 0, 0]), (b, [1, 0, 1])):
            px, py = proj.pixel(centre)                                   # the quad's centre (flat: y = 0)
            self.assertAlmostEqual(tile["center_px"][0], px, places=2)
            self.assertAlmostEqual(tile["center_px"][1], py, places=2)
            x0, y0, x1, y1 = tile["inner"]
            self.assertLessEqual(abs((x0 + x1) / 2 - px), 1)
            self.assertLessEqual(abs((y0 + y1) / 2 - py), 1)
            corners = [proj.pixel([centre[0] + dx, 0, centre[2] + dz]) for dx in (-0.5, 0.5) for dz in (-0.5, 0.5)]
            bx0, by0, bx1, by1 = tile["bbox"]
            self.assertEqual([bx0, by0], [math.floor(min(c[0] for c in corners)), math.floor(min(c[1] for c in corners))])
            self.assertEqual([bx1, by1], [math.ceil(max(c[0] for c in corners)), math.ceil(max(c[1] for c in corners))])
            self.assertTrue(bx0 < x0 < x1 < bx1 and by0 < y0 < y1 < by1)
        self.assertLess(a["center_px"][0], 160)                           # -x on the left
        self.assertGreater(b["center_px"][1], a["center_px"][1])           # nearer: lower in the image
        out = os.path.join(self.tmp, "regions.json")
        self.assertEqual(mp.main(["regions", path, "--width", "320", "--height", "180", "-o", out]), 0)
        with open(out) as f:
            self.assertEqual(json.load(f)["tiles"], regions["tiles"])


class PassPlanTest(unittest.TestCase):
    def test_plans(self):
        self.assertEqual(mp.pass_plan(1920, 1080, 300, "symbolic", 2 ** 26, "auto"), [300])
        plan = mp.pass_plan(1920, 1080, 300, "evaluated", 2 ** 26, "auto")
        self.assertEqual(sum(plan), 300)
        self.assertTrue(all(1920 * 1080 * p <= 2 ** 26 for p in plan))
        self.assertEqual(mp.pass_plan(10, 10, 7, "symbolic", 2 ** 26, "3"), [3, 2, 2])


class MicrofacetMaterialTest(Base):
    """conductor, glass and plastic (include/wavetrace/bsdfs/)."""

    def bsdfs(self, materials, **kw):
        spheres = [{"center": [3 * k, 0, 0], "radius": 1, "material": m["name"]} for k, m in enumerate(materials)]
        conv = self.convert(scene_doc(materials=materials, spheres=spheres), **kw)
        return conv, [self.bsdf_of(conv, s) for s in self.shapes(conv, "sphere")]

    def test_conductors(self):
        presets = mp.conductor_presets()
        conv, b = self.bsdfs([
            {"name": "mirror", "type": "conductor", "metal": "gold"},
            {"name": "rough", "type": "conductor", "metal": "copper", "roughness": 0.5},
            {"name": "brushed", "type": "conductor", "metal": "silver", "roughness": 0.5, "anisotropy": 0.8},
            {"name": "given", "type": "conductor", "eta": [0.2, 0.9, 1.1], "k": [3.9, 2.4, 2.1], "roughness": 0.1},
            {"name": "nearly", "type": "conductor", "metal": "iron", "roughness": 0.009},
        ])
        for x in b:
            self.assertEqual(x["type"], "twosided")              # two-sided on spheres too
        mirror, rough, brushed, given, nearly = [x["bsdf"] for x in b]
        self.assertEqual(mirror["type"], "conductor")
        self.assertNotIn("material", mirror)                     # eta and k, or Mitsuba refuses both
        self.assertEqual(mirror["eta"]["value"], list(presets["gold"][0]))
        self.assertEqual(mirror["k"]["value"], list(presets["gold"][1]))
        self.assertEqual((rough["type"], rough["distribution"], rough["sample_visible"]),
                         ("roughconductor", "ggx", True))
        self.assertAlmostEqual(rough["alpha"], 0.25)
        self.assertNotIn("alpha_u", rough)
        aspect = math.sqrt(1 - 0.9 * 0.8)
        self.assertAlmostEqual(brushed["alpha_u"], 0.25 / aspect)
        self.assertAlmostEqual(brushed["alpha_v"], 0.25 * aspect)
        self.assertNotIn("alpha", brushed)
        self.assertEqual(given["eta"]["value"], [0.2, 0.9, 1.1])
        self.assertEqual(given["k"]["value"], [3.9, 2.4, 2.1])
        self.assertAlmostEqual(given["alpha"], 0.01)
        self.assertEqual(nearly["type"], "conductor")            # alpha 8.1e-5: a mirror in wavetrace
        notes = " ".join(conv.notes)
        self.assertIn("Kulla-Conty", notes)
        self.assertIn("roughconductor has none", notes)
        self.assertIn("Smith masking", notes)

    def test_compensation_off_and_smooth_need_no_note(self):
        conv, _ = self.bsdfs([
            {"name": "single", "type": "conductor", "metal": "gold", "roughness": 0.5, "energy_compensation": False},
            {"name": "mirror", "type": "conductor", "metal": "gold"},
            {"name": "rough-single", "type": "glass", "roughness": 0.5, "energy_compensation": False},
            {"name": "smooth", "type": "glass"},
        ])
        self.assertFalse(any("energy_compensation" in n for n in conv.notes))
        self.assertTrue(any("Smith masking" in n for n in conv.notes))
        conv, _ = self.bsdfs([{"name": "mirror", "type": "conductor", "metal": "gold"},
                              {"name": "smooth", "type": "glass"},
                              {"name": "thin", "type": "glass", "thin": True}])
        self.assertEqual(conv.notes, [])

    def test_separable_masking_is_mitsubas(self):
        rough = [{"name": "c", "type": "conductor", "metal": "gold", "roughness": 0.5},
                 {"name": "f", "type": "conductor", "f0": [0.9, 0.7, 0.6], "roughness": 0.5},
                 {"name": "g", "type": "glass", "roughness": 0.5},
                 {"name": "p", "type": "plastic", "albedo": [0.5, 0.5, 0.5], "roughness": 0.5}]
        for m in rough:
            single = dict(m, energy_compensation=False) if m["type"] != "plastic" else dict(m)
            conv, _ = self.bsdfs([dict(single, masking="separable")])
            self.assertFalse(any("Smith" in n or "energy_compensation" in n for n in conv.notes), m["name"])
            for masking in (None, "height-correlated"):
                conv, _ = self.bsdfs([single if masking is None else dict(single, masking=masking)])
                self.assertIn(mp.SMITH_NOTE, conv.notes, m["name"])
        # Separable but compensated: the masking is Mitsuba's, the compensation not.
        conv, _ = self.bsdfs([dict(rough[0], masking="separable")])
        self.assertNotIn(mp.SMITH_NOTE, conv.notes)
        self.assertTrue(any("Kulla-Conty" in n for n in conv.notes))
        # Smooth ones need no note either way.
        conv, _ = self.bsdfs([dict(m, roughness=0) for m in rough])
        self.assertFalse(any("Smith" in n for n in conv.notes))
        with self.assertRaises(mp.ConversionError):
            self.bsdfs([dict(rough[0], masking="uncorrelated")])

    def test_f0_conductor_is_principled_metallic(self):
        conv, b = self.bsdfs([
            {"name": "f0", "type": "conductor", "f0": [0.9, 0.7, 0.6], "roughness": 0.3, "anisotropy": 0.5},
            {"name": "f0-mirror", "type": "conductor", "f0": [0.9, 0.7, 0.6], "energy_compensation": False},
        ])
        p = b[0]["bsdf"]
        self.assertEqual(b[0]["type"], "twosided")
        self.assertEqual((p["type"], p["metallic"], p["roughness"], p["anisotropic"]), ("principled", 1.0, 0.3, 0.5))
        self.assertEqual(p["base_color"]["value"], [0.9, 0.7, 0.6])
        self.assertNotIn("anisotropic", b[1]["bsdf"])
        notes = " ".join(conv.notes)
        self.assertIn("principled, metallic 1", notes)
        self.assertIn("principled has none", notes)                  # the compensated rough one
        self.assertIn("'f0-mirror' (f0, roughness 0): principled keeps each alpha >= 0.001", notes)

    def test_glass(self):
        conv, b = self.bsdfs([
            {"name": "smooth", "type": "glass"},
            {"name": "rough", "type": "glass", "ior": 1.33, "roughness": 0.4, "tint": [0.9, 1, 0.8]},
            {"name": "thin", "type": "glass", "ior": 1.6, "thin": True, "tint": [1, 0.5, 0.5]},
            {"name": "matched", "type": "glass", "ior": 1, "roughness": 0.5},
        ])
        smooth, rough, thin, matched = b
        self.assertEqual(smooth, {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0})   # not two-sided-wrapped
        self.assertEqual((rough["type"], rough["distribution"], rough["int_ior"], rough["sample_visible"]),
                         ("roughdielectric", "ggx", 1.33, True))
        self.assertAlmostEqual(rough["alpha"], 0.16)
        self.assertEqual(rough["specular_transmittance"]["value"], [0.9, 1.0, 0.8])
        self.assertNotIn("specular_reflectance", rough)             # the tint is on transmission only
        self.assertEqual((thin["type"], thin["int_ior"]), ("thindielectric", 1.6))
        self.assertEqual(thin["specular_transmittance"]["value"], [1.0, 0.5, 0.5])
        self.assertEqual((matched["type"], matched["int_ior"]), ("dielectric", 1.0))
        self.assertTrue(any("roughdielectric has none" in n and "Turquin" in n for n in conv.notes))

    def test_rough_thin_glass_is_refused(self):
        with self.assertRaises(mp.ConversionError):
            self.bsdfs([{"name": "bad", "type": "glass", "thin": True, "roughness": 0.1}])

    def test_plastic(self):
        textures = [{"name": "tiles", "type": "checker", "size": 1, "even": [1, 1, 1], "odd": [0.5, 0.5, 0.5]}]
        materials = [
            {"name": "smooth", "type": "plastic", "albedo": [0.8, 0.2, 0.1]},
            {"name": "rough", "type": "plastic", "albedo": [0.1, 0.2, 0.8], "ior": 1.4, "roughness": 0.6},
            {"name": "tiled", "type": "plastic", "texture": "tiles", "roughness": 0.2},
        ]
        spheres = [{"center": [3 * k, 0, 0], "radius": 1, "material": m["name"]} for k, m in enumerate(materials)]
        conv = self.convert(scene_doc(materials=materials, spheres=spheres, textures=textures))
        b = [self.bsdf_of(conv, s) for s in self.shapes(conv, "sphere")]
        for x in b:
            self.assertEqual(x["type"], "twosided")
        smooth, rough, tiled = [x["bsdf"] for x in b]
        self.assertEqual((smooth["type"], smooth["int_ior"], smooth["ext_ior"], smooth["nonlinear"]),
                         ("plastic", 1.5, 1.0, True))
        self.assertEqual(smooth["diffuse_reflectance"]["value"], [0.8, 0.2, 0.1])
        self.assertNotIn("specular_reflectance", smooth)            # Mitsuba's default, 1
        self.assertEqual((rough["type"], rough["distribution"], rough["int_ior"], rough["nonlinear"]),
                         ("roughplastic", "ggx", 1.4, True))
        self.assertAlmostEqual(rough["alpha"], 0.36)
        self.assertEqual(tiled["diffuse_reflectance"]["type"], "wt_checker")
        notes = " ".join(conv.notes)
        self.assertIn("smooth plastic, ior 1.5", notes)
        self.assertIn("Smith masking", notes)
        self.assertNotIn("energy_compensation", notes)              # plastic has no compensation

    def test_diffuse_fresnel(self):
        # The integral wavetrace uses and Mitsuba's fit agree to 0.2% for glass-like indices.
        for ior in (1.33, 1.5, 1.7):
            exact, fit = mp.diffuse_fresnel(1 / ior), mp.mitsuba_diffuse_fresnel(1 / ior)
            self.assertLess(abs(fit / exact - 1), 2e-3)
        self.assertAlmostEqual(mp.diffuse_fresnel(1 / 1.5), 0.59635, places=4)


class TexturedMaterialTest(Base):
    """roughness_texture and normal_texture (include/wavetrace/bsdf.hpp's bsdf_at)."""

    TEXTURES = [
        {"name": "squares", "type": "checker", "size": 0.5, "even": [1, 1, 1], "odd": [0.3, 0.2, 0.1]},
        {"name": "veins", "type": "noise", "scale": 4, "high": [1, 0.8, 1], "low": [0, 0.4, 0]},
        {"name": "map", "type": "image", "file": os.path.join(ROOT, "scenes/textures/bumps_normal.png"),
         "colorspace": "linear", "wrap": "repeat"},
        {"name": "map_srgb", "type": "image", "file": os.path.join(ROOT, "scenes/textures/bumps_normal.png")},
    ]

    def bsdfs(self, materials, **kw):
        spheres = [{"center": [3 * k, 0, 0], "radius": 1, "material": m["name"]} for k, m in enumerate(materials)]
        conv = self.convert(scene_doc(textures=self.TEXTURES, materials=materials, spheres=spheres), **kw)
        return conv, [self.bsdf_of(conv, s) for s in self.shapes(conv, "sphere")]

    def test_roughness_texture_scales_alpha_where_mitsuba_takes_a_texture(self):
        conv, b = self.bsdfs([
            {"name": "c", "type": "conductor", "metal": "gold", "roughness": 0.6, "roughness_texture": "squares"},
            {"name": "default", "type": "conductor", "metal": "gold", "roughness_texture": "squares"},
            {"name": "aniso", "type": "conductor", "metal": "gold", "roughness": 0.5, "anisotropy": 0.8,
             "roughness_texture": "map"},
            {"name": "f0", "type": "conductor", "f0": [0.9, 0.8, 0.7], "roughness": 0.4,
             "roughness_texture": "squares"},
            {"name": "g", "type": "glass", "roughness": 0.7, "roughness_texture": "squares"},
            {"name": "smooth", "type": "conductor", "metal": "gold", "roughness": 0, "roughness_texture": "squares"},
        ])
        c, default, aniso, f0, g, smooth = b
        alpha = c["bsdf"]["alpha"]
        self.assertEqual((alpha["type"], alpha["scale"], alpha["power"]), ("wt_roughness", 0.36, 2.0))
        checker = alpha["texture"]
        self.assertEqual((checker["type"], checker["odd_g"]), ("wt_checker", 0.2))
        self.assertEqual([checker["ox%d" % k] for k in range(4)], [1.0, 0.0, 0.0, 0.0])   # the sphere at x = 0
        self.assertEqual(default["bsdf"]["alpha"]["scale"], 1.0)          # roughness 1 with a roughness texture
        aspect = math.sqrt(1 - 0.9 * 0.8)
        self.assertAlmostEqual(aniso["bsdf"]["alpha_u"]["scale"], 0.25 / aspect)
        self.assertAlmostEqual(aniso["bsdf"]["alpha_v"]["scale"], 0.25 * aspect)
        self.assertEqual(aniso["bsdf"]["alpha_u"]["texture"]["type"], "bitmap")
        self.assertEqual(aniso["bsdf"]["alpha_u"]["texture"]["raw"], True)
        rough = f0["bsdf"]["roughness"]                                  # principled squares it itself
        self.assertEqual((rough["type"], rough["scale"], rough["power"]), ("wt_roughness", 0.4, 1.0))
        self.assertEqual(g["type"], "roughdielectric")
        self.assertAlmostEqual(g["alpha"]["scale"], 0.49)
        self.assertEqual(smooth["bsdf"]["type"], "conductor")             # 0 times anything: a mirror
        self.assertIn("wt_roughness", conv.python_plugins)
        self.assertIn("wt_checker", conv.python_plugins)
        self.assertFalse(any("roughness_texture" in n for n in conv.notes))
        # A checker is a function of the object-space point: one BSDF per sphere.
        doc = scene_doc(textures=self.TEXTURES, materials=[{"name": "c", "type": "conductor", "metal": "gold",
                                                             "roughness_texture": "squares"}],
                        spheres=[{"center": [k, 0, 0], "radius": 0.2, "material": "c"} for k in range(2)])
        shapes = self.shapes(self.convert(doc), "sphere")
        self.assertEqual([s["bsdf"]["type"] for s in shapes], ["twosided", "twosided"])
        self.assertEqual(shapes[1]["bsdf"]["bsdf"]["alpha"]["texture"]["ox3"], -1.0)

    def test_roughness_texture_falls_back_to_its_mean(self):
        conv, b = self.bsdfs([
            {"name": "p", "type": "plastic", "roughness": 0.5, "roughness_texture": "squares"},
            {"name": "n", "type": "conductor", "metal": "gold", "roughness": 0.5, "roughness_texture": "veins"},
            {"name": "i", "type": "plastic", "roughness": 0.5, "roughness_texture": "map"},
        ])
        p, n, i = b
        self.assertAlmostEqual(p["bsdf"]["alpha"], (0.5 * 0.6) ** 2)     # (even + odd) / 2 = 0.6
        self.assertAlmostEqual(n["bsdf"]["alpha"], (0.5 * 0.6) ** 2)     # (high + low) / 2 = 0.6
        self.assertEqual(i["bsdf"]["alpha"], {"__green_mean__": {
            "file": os.path.join(ROOT, "scenes/textures/bumps_normal.png"), "srgb": False, "scale": 0.25,
            "power": 2.0}})
        notes = " ".join(conv.notes)
        self.assertIn("roughness_texture 'squares' of 'p': the textured roughness does not map exactly: "
                      "Mitsuba's roughplastic takes one alpha", notes)
        self.assertIn("roughness_texture 'veins' of 'n'", notes)
        self.assertIn("a noise texture has no Mitsuba counterpart", notes)
        self.assertIn("its mean green over the texels", notes)
        conv, b = self.bsdfs([{"name": "c", "type": "conductor", "metal": "gold", "roughness": 0.5,
                               "roughness_texture": "squares"}], python_plugins=False)
        self.assertAlmostEqual(b[0]["bsdf"]["alpha"], (0.5 * 0.6) ** 2)
        self.assertIn("cannot square a texture", " ".join(conv.notes))
        self.assertEqual(conv.python_plugins, [])

    def test_normal_map_wraps_the_bsdf(self):
        conv, b = self.bsdfs([
            {"name": "p", "type": "plastic", "roughness": 0.3, "normal_texture": "map"},
            {"name": "l", "type": "lambertian", "normal_texture": "map", "normal_strength": 0.5},
            {"name": "g", "type": "glass", "roughness": 0.2, "normal_texture": "map"},
            {"name": "flat", "type": "lambertian", "normal_texture": "map", "normal_strength": 0},
            {"name": "proc", "type": "conductor", "metal": "gold", "normal_texture": "squares"},
        ])
        p, l, g, flat, proc = b
        self.assertEqual((p["type"], p["flip_invalid_normals"], p["use_shadowing_function"]),
                         ("normalmap", True, False))
        self.assertEqual(p["bsdf"]["type"], "twosided")                  # the map outside: it turns with the back
        self.assertEqual(p["bsdf"]["bsdf"]["type"], "roughplastic")
        nm = p["normalmap"]
        self.assertEqual((nm["type"], nm["raw"], nm["wrap_mode"]), ("bitmap", True, "repeat"))
        self.assertEqual(nm["to_uv"]["__transform__"], mp.SPHERE_TO_UV)
        self.assertEqual((l["type"], l["bsdf"]["type"]), ("normalmap", "diffuse"))
        self.assertEqual((g["type"], g["bsdf"]["type"]), ("normalmap", "roughdielectric"))
        self.assertEqual(flat["type"], "diffuse")                         # strength 0: no perturbation
        self.assertEqual(proc["type"], "twosided")                        # not mapped
        notes = " ".join(conv.notes)
        # The strength scales the map's x and y before Mitsuba normalises it.
        self.assertEqual((l["normalmap"]["type"], l["normalmap"]["strength"]), ("wt_normal_scale", 0.5))
        self.assertEqual(l["normalmap"]["texture"]["type"], "bitmap")
        self.assertEqual(p["normalmap"]["type"], "bitmap")               # strength 1: the map itself
        for fragment in ("normal_texture 'squares' of 'proc': a checker texture "
                         "used as a normal map does not map", "normal maps on spheres", "flip_invalid_normals",
                         "its y (green) the same way"):
            self.assertIn(fragment, notes)
        self.assertNotIn("normal maps on meshes", notes)
        self.assertIn("normalmap", conv.plugins())
        with self.assertRaisesRegex(mp.ConversionError, "colorspace"):
            self.bsdfs([{"name": "s", "type": "lambertian", "normal_texture": "map_srgb"}])

    def test_a_bump_map_wraps_the_bsdf(self):
        conv, b = self.bsdfs([{"name": "l", "type": "lambertian", "bump_texture": "map", "bump_scale": 0.1},
                              {"name": "p", "type": "plastic", "roughness": 0.3, "bump_texture": "map"},
                              {"name": "flat", "type": "lambertian", "bump_texture": "map", "bump_scale": 0}])
        l, p, flat = b
        self.assertEqual((l["type"], l["scale"], l["bsdf"]["type"]), ("bumpmap", 0.1, "diffuse"))
        self.assertEqual((l["arbitrary"]["type"], l["arbitrary"]["raw"]), ("bitmap", True))
        self.assertEqual((p["type"], p["scale"], p["bsdf"]["type"]), ("bumpmap", 1.0, "twosided"))
        self.assertEqual(flat["type"], "diffuse")                         # scale 0: no perturbation
        self.assertIn("bump maps: both displace", " ".join(conv.notes))
        self.assertIn("bumpmap", conv.plugins())

    def test_normal_map_on_a_mesh(self):
        conv = mp.convert(os.path.join(ROOT, "scenes", "materials-single.json"))
        maps = [v for v in conv.scene.values() if isinstance(v, dict) and v.get("type") == "normalmap"]
        self.assertEqual(len(maps), 1)
        self.assertEqual(maps[0]["normalmap"]["filename"], os.path.join(ROOT, "scenes", "textures", "bumps_normal.png"))
        self.assertNotIn("to_uv", maps[0]["normalmap"])
        notes = " ".join(conv.notes)
        self.assertIn("normal maps on meshes", notes)
        self.assertIn("the frames agree where a triangle's UVs are not mirrored", notes)
        self.assertNotIn("Mitsuba's bitmap wraps", notes)                 # "wrap": "repeat" on both axes

    def test_image_wrap_modes(self):
        path = os.path.join(ROOT, "scenes/textures/planet.png")
        textures = [{"name": "a", "type": "image", "file": path},
                    {"name": "b", "type": "image", "file": path, "wrap": "clamp"},
                    {"name": "c", "type": "image", "file": path, "wrap": ["mirror", "mirror"], "uv_scale": [2, 2]}]
        materials = [{"name": k, "type": "lambertian", "texture": k} for k in "abc"]
        spheres = [{"center": [3 * i, 0, 0], "radius": 1, "material": k} for i, k in enumerate("abc")]
        conv = self.convert(scene_doc(textures=textures, materials=materials, spheres=spheres))
        modes = [self.bsdf_of(conv, s)["reflectance"]["wrap_mode"] for s in self.shapes(conv, "sphere")]
        self.assertEqual(modes, ["repeat", "clamp", "mirror"])
        notes = " ".join(conv.notes)
        self.assertIn("wavetrace repeat u and clamp v", notes)            # the default: [repeat, clamp]
        # uv_scale (2, 2) after the sphere's own turn: to_uv = scale x SPHERE_TO_UV.
        c = self.bsdf_of(conv, self.shapes(conv, "sphere")[2])["reflectance"]
        self.assertEqual(c["to_uv"]["__transform__"], mp.mat_mul(mp.mat_scale([2, 2, 1]), mp.SPHERE_TO_UV))
        self.assertNotIn("not converted", notes)


class ConductorPresetsTest(Base):
    def test_the_repository_header(self):
        presets = mp.conductor_presets()
        with open(mp.CONDUCTOR_PRESETS_HEADER) as f:
            entries = [line for line in f if line.lstrip().startswith('{"')]
        self.assertEqual(len(presets), len(entries))                  # the regex reads every entry
        self.assertEqual(presets["gold"], ((0.188, 0.544, 1.332), (3.403, 2.231, 1.869)))
        for name in ("silver", "copper", "aluminium", "iron", "chromium", "titanium", "nickel", "platinum"):
            eta, k = presets[name]
            self.assertTrue(all(x > 0 for x in eta + k), name)

    def conductor(self, metal):
        return self.convert(scene_doc(materials=[{"name": "g", "type": "conductor", "metal": metal}],
                                      spheres=[{"center": [0, 0, 0], "radius": 1, "material": "g"}]))

    def test_a_missing_preset_is_an_error_naming_the_file(self):
        path = os.path.join(self.tmp, "presets.hpp")
        with open(path, "w") as f:
            f.write('    {"gold", vec3(0.1f, 0.2f, 0.3f), vec3(1.0f, 2.0f, 3.0f)},\n')
        self.assertEqual(mp.conductor_presets(path), {"gold": ((0.1, 0.2, 0.3), (1.0, 2.0, 3.0))})
        old = mp.CONDUCTOR_PRESETS_HEADER
        try:
            mp.CONDUCTOR_PRESETS_HEADER = path
            with self.assertRaisesRegex(mp.ConversionError, "'silver' is not in .*presets.hpp"):
                self.conductor("silver")
            mp.CONDUCTOR_PRESETS_HEADER = os.path.join(self.tmp, "absent.hpp")
            with self.assertRaisesRegex(mp.ConversionError, "absent.hpp"):
                self.conductor("gold")
        finally:
            mp.CONDUCTOR_PRESETS_HEADER = old
        with self.assertRaisesRegex(mp.ConversionError, "conductor_presets.hpp"):
            self.conductor("unobtainium")
        with self.assertRaises(mp.ConversionError):
            self.conductor("Gold")                                    # wavetrace's names are exact


class MaterialScenesTest(Base):
    """scenes/materials*.json and cornell-materials*.json (tools/make_materials.py)."""

    def test_committed_scenes_are_the_generators(self):
        import make_materials as mm
        import scenefile
        names = {"room": "cornell-materials-room.obj", "short_block": "cornell-materials-short-block.obj",
                 "tall_block": "cornell-materials-tall-block.obj"}
        for file, scene in (("materials.json", mm.build_table()),
                            ("materials-single.json", mm.build_table(single=True)),
                            ("cornell-materials.json", mm.build_cornell(names)),
                            ("cornell-materials-single.json", mm.build_cornell(names, single=True))):
            with open(os.path.join(ROOT, "scenes", file)) as f:
                self.assertEqual(f.read(), scenefile.dumps_scene(scene), file)

    def test_committed_plane_is_the_generators(self):
        import make_materials as mm
        mm.write_plane(self.tmp)
        for name in (mm.PLANE_STEM + ".obj",):
            with open(os.path.join(self.tmp, name)) as a, open(os.path.join(ROOT, "scenes", name)) as b:
                self.assertEqual(a.read(), b.read(), name)

    def test_plane_faces_up_with_a_right_handed_uv_frame(self):
        # wavetrace's tangent_sign (geometry.hpp) is +1 where cross(n, dp/du) runs
        # against dp/dv (v = 1 - OBJ's v): there Mitsuba's t = cross(n, s) is
        # wavetrace's bitangent, so the two tangent frames agree.
        import make_materials as mm
        corners, uvs = mm.plane_corners()
        for tri in ((0, 1, 2), (0, 2, 3)):
            p = [corners[i] for i in tri]
            t = [(uvs[i][0], 1 - uvs[i][1]) for i in tri]
            e1, e2 = [[p[k][i] - p[0][i] for i in range(3)] for k in (1, 2)]
            n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
            self.assertGreater(n[1], 0)
            d1, d2 = [[t[k][i] - t[0][i] for i in range(2)] for k in (1, 2)]
            det = d1[0] * d2[1] - d1[1] * d2[0]
            dpdu = [(d2[1] * e1[i] - d1[1] * e2[i]) / det for i in range(3)]
            dpdv = [(d1[0] * e2[i] - d2[0] * e1[i]) / det for i in range(3)]
            b = [n[1] * dpdu[2] - n[2] * dpdu[1], n[2] * dpdu[0] - n[0] * dpdu[2], n[0] * dpdu[1] - n[1] * dpdu[0]]
            self.assertLess(sum(x * y for x, y in zip(b, dpdv)), 0)
            self.assertLess(dpdu[0], 0)                                 # u along -x: the image's right
            self.assertGreater(b[2], 0)                                 # up the image: +z, away from the camera

    def test_single_is_mitsubas_models(self):
        for stem in ("materials", "cornell-materials"):
            with open(os.path.join(ROOT, "scenes", stem + ".json")) as f:
                full = json.load(f)
            with open(os.path.join(ROOT, "scenes", stem + "-single.json")) as f:
                single = json.load(f)
            for a, b in zip(full["materials"], single["materials"]):
                self.assertNotIn("energy_compensation", a)               # wavetrace's defaults
                self.assertNotIn("masking", a)
                if a["type"] in ("conductor", "glass"):
                    self.assertIs(b.pop("energy_compensation"), False)
                if a["type"] in ("conductor", "glass", "plastic"):
                    self.assertEqual(b.pop("masking"), "separable")
                self.assertEqual(a, b)
            conv = mp.convert(os.path.join(ROOT, "scenes", stem + "-single.json"))
            self.assertFalse(any("energy_compensation" in n or "Smith" in n for n in conv.notes), stem)
            conv = mp.convert(os.path.join(ROOT, "scenes", stem + ".json"))
            notes = " ".join(conv.notes)
            for word in ("Kulla-Conty", "Turquin", "Smith masking"):
                self.assertIn(word, notes, stem)

    def test_regions(self):
        import make_materials as mm
        scene = mm.build_table()
        for w, h in ((1920, 1080), (960, 540)):
            regs = mm.regions(scene, w, h)
            planes = mm.plane_regions(scene, w, h)
            self.assertEqual(len(regs), len(scene["spheres"]) - 1)
            self.assertEqual([p["material"] for p in planes], ["bumpy-plastic"])
            self.assertEqual(mm.overlapping(regs + planes, w, h), [])
            proj = mm.Projection(scene["camera"], w, h)
            for p in planes:
                x0, y0, x1, y1 = p["bbox"]
                ix0, iy0, ix1, iy1 = p["inner"]
                self.assertTrue(x0 < ix0 < ix1 < x1 and y0 < iy0 < iy1 < y1)
                corners = [proj.pixel(c) for c in p["corners"]]
                self.assertEqual([x0, y0], [math.floor(min(c[0] for c in corners)),
                                            math.floor(min(c[1] for c in corners))])
                self.assertEqual([x1, y1], [math.ceil(max(c[0] for c in corners)),
                                            math.ceil(max(c[1] for c in corners))])
            for r in regs:
                x0, y0, x1, y1 = r["bbox"]
                ix0, iy0, ix1, iy1 = r["inner"]
                self.assertTrue(x0 < ix0 < ix1 < x1 and y0 < iy0 < iy1 < y1, r["material"])
                cx, cy = r["center_px"]
                self.assertTrue(proj.sees(cx, cy, r["center"], r["radius"]))
                # The box is tight: just outside each side, the sphere is missed.
                self.assertFalse(proj.sees(x0 - 0.01, cy, r["center"], r["radius"]))
                self.assertFalse(proj.sees(x1 + 0.01, cy, r["center"], r["radius"]))
                self.assertFalse(proj.sees(cx, y0 - 0.01, r["center"], r["radius"]))
                self.assertFalse(proj.sees(cx, y1 + 0.01, r["center"], r["radius"]))

    def test_projection_is_the_peers_camera(self):
        # make_materials' pixel mapping and the peer's Mitsuba camera agree: a
        # point on the camera's axis lands in the image's centre, and +x (the
        # camera's left in Mitsuba's look_at frame) lands left of it.
        import make_materials as mm
        cam = mm.build_table()["camera"]
        proj = mm.Projection(cam, 1920, 1080)
        px, py = proj.pixel(cam["look_at"])
        self.assertAlmostEqual(px, 960, places=6)
        self.assertAlmostEqual(py, 540, places=6)
        m = mp.look_at_matrix(cam["look_from"], cam["look_at"], cam["up"])
        left = col(m, 0)
        p = [cam["look_at"][i] + left[i] for i in range(3)]
        self.assertLess(proj.pixel(p)[0], 960)


def mitsuba_available():
    try:
        import mitsuba  # noqa: F401
        return "scalar_rgb" in mitsuba.variants()
    except ImportError:
        return False


@unittest.skipUnless(mitsuba_available(), "Mitsuba 3 is not installed for this Python")
class MitsubaModelTest(Base):
    """What the conversion relies on in Mitsuba itself (scalar_rgb; skipped without Mitsuba)."""

    def setUp(self):
        super().setUp()
        import mitsuba as mi
        mi.set_variant("scalar_rgb")
        self.mi = mi

    def sphere_frames(self):
        """(Mitsuba's shading frame (s, t), wavetrace's unit tangent T, the normal n)
        at three hits of a sphere placed as the converter places one."""
        mi, dr = self.mi, __import__("drjit")
        c, r = [1.0, 2.0, 3.0], 0.7
        to_world = mp.mat_mul(mp.mat_mul(mp.mat_translate(c), mp.SPHERE_FRAME), mp.mat_scale(r))
        sphere = {"type": "sphere", "to_world": mp.realize(mi, mp.transform(to_world))}
        scene = mi.load_dict({"type": "scene", "s": sphere})
        out = []
        for d in ([0.3, -0.2, 1.0], [-0.5, 0.4, 1.0], [0.1, 0.6, -1.0]):
            si = scene.ray_intersect(mi.Ray3f([c[i] - 5 * d[i] for i in range(3)], dr.normalize(mi.Vector3f(d))))
            n = [si.n.x, si.n.y, si.n.z]
            t = [-n[2], 0.0, n[0]]
            ln = math.sqrt(sum(x * x for x in t))
            out.append(([si.sh_frame.s.x, si.sh_frame.s.y, si.sh_frame.s.z],
                        [si.sh_frame.t.x, si.sh_frame.t.y, si.sh_frame.t.z], [x / ln for x in t], n))
        return out

    def test_sphere_tangent_is_wavetraces_azimuth(self):
        # Anisotropic alpha_u runs along Mitsuba's sh_frame.s (dp/du); wavetrace's
        # alpha_x along a sphere's dp/du = (-n.z, 0, n.x): the same axis.
        for s, _, t, _ in self.sphere_frames():
            self.assertAlmostEqual(abs(sum(a * b for a, b in zip(s, t))), 1.0, places=5)

    def test_principled_metallic_is_schlick_ggx(self):
        mi, dr = self.mi, __import__("drjit")
        f0, rough, aniso = [0.96, 0.74, 0.64], 0.5, 0.6
        m = {"name": "f", "type": "conductor", "f0": f0, "roughness": rough, "anisotropy": aniso,
             "energy_compensation": False}
        conv = self.convert(scene_doc(materials=[m], spheres=[{"center": [0, 0, 0], "radius": 1, "material": "f"}]))
        p = mi.load_dict(mp.realize(mi, self.bsdf_of(conv, self.shapes(conv, "sphere")[0])["bsdf"]))
        aspect = math.sqrt(1 - 0.9 * aniso)
        white = mi.load_dict({"type": "roughconductor", "distribution": "ggx", "alpha_u": rough ** 2 / aspect,
                              "alpha_v": rough ** 2 * aspect, "eta": {"type": "rgb", "value": [0.0] * 3},
                              "k": {"type": "rgb", "value": [1.0] * 3}})      # F = 1 everywhere
        ctx = mi.BSDFContext()
        si = dr.zeros(mi.SurfaceInteraction3f)
        si.sh_frame = mi.Frame3f([0, 0, 1])
        for wi, wo in (([0.3, 0.1, 0.9], [-0.4, 0.2, 0.8]), ([0.7, -0.2, 0.3], [-0.1, 0.5, 0.6])):
            si.wi = dr.normalize(mi.Vector3f(wi))
            w = dr.normalize(mi.Vector3f(wo))
            c = dr.dot(si.wi, dr.normalize(si.wi + w))
            a, b = p.eval(ctx, si, w), white.eval(ctx, si, w)
            for k in range(3):
                self.assertAlmostEqual(a[k] / b[k], f0[k] + (1 - f0[k]) * (1 - c) ** 5, places=5)

    def test_roughconductor_masks_separably(self):
        # "masking": "separable" is Mitsuba's G: a white roughconductor's f cos is
        # D G1(wi) G1(wo) / (4 cos_i), with microfacet.hpp's D and Lambda.
        mi, dr = self.mi, __import__("drjit")
        ax, ay = 0.9, 0.4
        b = mi.load_dict({"type": "roughconductor", "distribution": "ggx", "alpha_u": ax, "alpha_v": ay,
                          "eta": {"type": "rgb", "value": [0.0] * 3}, "k": {"type": "rgb", "value": [1.0] * 3}})

        def lam(w):
            return 0.5 * (math.sqrt(1 + (ax * ax * w[0] ** 2 + ay * ay * w[1] ** 2) / w[2] ** 2) - 1)

        si = dr.zeros(mi.SurfaceInteraction3f)
        si.sh_frame = mi.Frame3f([0, 0, 1])
        for wi, wo in (([0.3, 0.1, 0.9], [-0.4, 0.2, 0.8]), ([0.9, -0.2, 0.15], [-0.8, 0.5, 0.2])):
            wi, wo = [[x / math.sqrt(sum(y * y for y in v)) for x in v] for v in (wi, wo)]
            h = [a + c for a, c in zip(wi, wo)]
            h = [x / math.sqrt(sum(y * y for y in h)) for x in h]
            d = 1 / (math.pi * ax * ay * ((h[0] / ax) ** 2 + (h[1] / ay) ** 2 + h[2] ** 2) ** 2)
            want = d / ((1 + lam(wi)) * (1 + lam(wo))) / (4 * wi[2])
            si.wi = mi.Vector3f(wi)
            self.assertAlmostEqual(b.eval(mi.BSDFContext(), si, mi.Vector3f(wo))[0] / want, 1.0, places=5)

    def test_sphere_frame_is_wavetraces_but_for_the_tangents_sign(self):
        # The normal-map note: on a sphere Mitsuba's s is wavetrace's -T (T the
        # azimuth, dp/du = (-n.z, 0, n.x)) and its t = cross(n, s) is wavetrace's
        # bitangent cross(n, T) x tangent_sign (-1 on spheres, sphere.hpp).
        for s_mi, t_mi, t, n in self.sphere_frames():
            b = [-(n[1] * t[2] - n[2] * t[1]), -(n[2] * t[0] - n[0] * t[2]), -(n[0] * t[1] - n[1] * t[0])]
            self.assertAlmostEqual(sum(a * e for a, e in zip(s_mi, t)), -1.0, places=5)
            self.assertAlmostEqual(sum(a * e for a, e in zip(t_mi, b)), 1.0, places=5)
            self.assertGreater(b[1], 0)                                  # up the image: towards +y

    def test_plane_frame_is_wavetraces(self):
        mi, dr = self.mi, __import__("drjit")
        shape = {"type": "obj", "filename": os.path.join(ROOT, "scenes", "materials-plane.obj"), "face_normals": True}
        scene = mi.load_dict({"type": "scene", "p": shape})
        for o in ([7, 5, 1], [6, 3, -4], [9, 2, 4]):
            si = scene.ray_intersect(mi.Ray3f(o, dr.normalize(mi.Vector3f(0, -1, 0.1))))
            self.assertTrue(close([si.n.x, si.n.y, si.n.z], [0, 1, 0], 1e-6))
            self.assertTrue(close([si.sh_frame.s.x, si.sh_frame.s.y, si.sh_frame.s.z], [-1, 0, 0], 1e-6))
            self.assertTrue(close([si.sh_frame.t.x, si.sh_frame.t.y, si.sh_frame.t.z], [0, 0, 1], 1e-6))

    def test_wt_roughness_is_the_squared_scaled_green(self):
        mi, dr = self.mi, __import__("drjit")
        doc = scene_doc(textures=[{"name": "sq", "type": "checker", "size": 1, "even": [1, 1, 1],
                                   "odd": [0.2, 0.5, 0.2]}],
                        materials=[{"name": "c", "type": "conductor", "metal": "gold", "roughness": 0.8,
                                    "roughness_texture": "sq", "energy_compensation": False,
                                    "masking": "separable"}],
                        spheres=[{"center": [0, 0, 0], "radius": 1, "material": "c"}])
        conv = self.convert(doc)
        mp.register_python_plugins(mi, dr, conv.python_plugins)
        b = mi.load_dict(mp.realize(mi, self.bsdf_of(conv, self.shapes(conv, "sphere")[0])["bsdf"]))
        presets = mp.conductor_presets()

        def plain(alpha):
            return mi.load_dict({"type": "roughconductor", "distribution": "ggx", "alpha": alpha,
                                 "eta": {"type": "rgb", "value": list(presets["gold"][0])},
                                 "k": {"type": "rgb", "value": list(presets["gold"][1])}})

        si = dr.zeros(mi.SurfaceInteraction3f)
        si.sh_frame = mi.Frame3f([0, 0, 1])
        si.wi = dr.normalize(mi.Vector3f(0.3, 0.1, 0.9))
        wo = dr.normalize(mi.Vector3f(-0.4, 0.2, 0.8))
        for p, g in (([0.5, 0, 0.5], 1.0), ([1.5, 0, 0.5], 0.5)):       # even, odd squares (the sphere at 0)
            si.p = mi.Point3f(p)
            want = plain((0.8 * g) ** 2).eval(mi.BSDFContext(), si, wo)
            got = b.eval(mi.BSDFContext(), si, wo)
            for k in range(3):
                self.assertAlmostEqual(got[k] / want[k], 1.0, places=5)

    def bumps_normal(self):
        import numpy as np
        path = os.path.join(ROOT, "scenes", "textures", "bumps_normal.png")
        return path, np.array(self.mi.Bitmap(path), dtype=np.int32)

    def test_normal_map_is_opengls_convention(self):
        # tools/make_textures.cpp's bumps: flat between them, tiling both ways, and
        # above a bump's centre (texel 32, 32) the normal leans up the image (green
        # high), right of it towards +u (red high).
        _, img = self.bumps_normal()
        self.assertEqual(img.shape, (256, 256, 3))
        self.assertEqual(list(img[0, 0]), [128, 128, 255])
        self.assertLessEqual(abs(img[0] - img[-1]).max(), 12)
        self.assertLessEqual(abs(img[:, 0] - img[:, -1]).max(), 12)
        self.assertGreater(img[32 - 13, 32, 1], 200)
        self.assertGreater(img[32, 32 + 13, 0], 200)

    def test_green_mean_of_an_image(self):
        path, img = self.bumps_normal()
        want = img[:, :, 1].sum() / 255.0 / img[:, :, 1].size
        self.assertAlmostEqual(mp.green_mean(self.mi, path, False), want, places=5)
        alpha = mp.realize(self.mi, {"__green_mean__": {"file": path, "srgb": False, "scale": 0.25, "power": 2.0}})
        self.assertAlmostEqual(alpha, 0.25 * want * want, places=5)

    def test_material_scenes_load(self):
        mi = self.mi
        for stem in ("materials", "materials-single", "cornell-materials", "cornell-materials-single"):
            conv = mp.convert(os.path.join(ROOT, "scenes", stem + ".json"), width=8, height=8, spp=1)
            scene = mp.load_scene(conv, "scalar_rgb")
            self.assertGreater(len(scene.shapes()), 0, stem)

    @unittest.skipUnless(os.path.isdir(os.path.join(ROOT, "scenes", "generated", "tiles")),
                         "the glTF tiles are not generated (build/wavetrace-gltf-tiles scenes/generated/tiles)")
    def test_gltf_tiles_load_and_render(self):
        conv = mp.convert(os.path.join(ROOT, "scenes", "gltf-tiles.json"), width=16, height=9, spp=1)
        scene = mp.load_scene(conv, "scalar_rgb")
        self.assertGreater(len(scene.emitters()), 3)
        self.mi.render(scene, spp=1)


class EmittedPluginsTest(Base):
    def test_every_emitted_plugin_is_listed(self):
        # scripts/peer-pack.sh keeps EMITTED_PLUGINS: every scene must stay inside it.
        for name in ("seed57", "rtiow-cover", "cornell-box", "glossy-lights", "quick", "sky-sun", "divergent",
                     "materials", "materials-single", "cornell-materials", "cornell-materials-single"):
            conv = mp.convert(os.path.join(ROOT, "scenes", name + ".json"))
            extra = set(conv.plugins()) - set(mp.EMITTED_PLUGINS) - set(mp.PYTHON_PLUGINS)
            self.assertEqual(extra, set(), name)
        if os.path.isdir(os.path.join(ROOT, "scenes", "generated", "tiles")):
            conv = mp.convert(os.path.join(ROOT, "scenes", "gltf-tiles.json"))
            self.assertEqual(set(conv.plugins()) - set(mp.EMITTED_PLUGINS) - set(mp.PYTHON_PLUGINS), set())

    def test_peer_pack_keeps_every_emitted_plugin(self):
        # scripts/peer-pack.sh's PLUGINS: what the trimmed package keeps ("scene" is
        # libmitsuba's; an "rgb" value loads the srgb plugin).
        import re
        with open(os.path.join(ROOT, "scripts", "peer-pack.sh")) as f:
            kept = set(re.search(r'^PLUGINS="([^"]*)"', f.read(), re.M).group(1).split())
        self.assertEqual(set(mp.EMITTED_PLUGINS) - kept - {"scene", "rgb"}, set())


class XmlTest(Base):
    """The dict written as Mitsuba XML (the `xml` command): every value in the
    element Mitsuba reads it from; wavetrace reads the shipped results back
    (tests/mitsuba_scene_test.cpp)."""

    def test_dict_as_xml(self):
        import xml.etree.ElementTree as ET
        doc = scene_doc(materials=[{"name": "gold", "type": "conductor", "metal": "gold", "roughness": 0.5,
                                    "masking": "separable", "energy_compensation": False}],
                        spheres=[{"center": [1, 2, 3], "radius": 0.5, "material": "gold"}])
        conv = self.convert(doc)
        root = ET.fromstring(mp.to_xml(conv.scene, self.tmp))
        self.assertEqual(root.tag, "scene")
        self.assertEqual(root.get("version"), "3.0.0")
        sensor = root.find("sensor")
        self.assertEqual(sensor.get("type"), "perspective")
        self.assertEqual(sensor.find("film").find("rfilter").get("type"), "box")
        self.assertEqual(len(sensor.find("transform").find("matrix").get("value").split()), 16)
        sphere = [e for e in root.findall("shape") if e.get("type") == "sphere"][0]
        ref = sphere.find("ref")
        bsdf = [e for e in root.findall("bsdf") if e.get("id") == ref.get("id")][0]
        inner = bsdf.find("bsdf") if bsdf.get("type") == "twosided" else bsdf
        self.assertEqual(inner.get("type"), "roughconductor")
        alpha = [e for e in inner.findall("float") if e.get("name") == "alpha"][0]
        self.assertAlmostEqual(float(alpha.get("value")), 0.25)
        self.assertEqual(len(inner.find("rgb").get("value").split(",")), 3)

    def test_python_plugins_refused(self):
        doc = scene_doc(textures=[{"name": "c", "type": "checker", "size": 1, "even": [1, 1, 1], "odd": [0, 0, 0]}],
                        materials=[{"name": "grey", "type": "lambertian", "texture": "c"}])
        path = os.path.join(self.tmp, "c.json")
        with open(path, "w") as f:
            json.dump(doc, f)
        self.assertEqual(mp.main(["xml", path, "-o", os.path.join(self.tmp, "c.xml")]), 2)
        self.assertFalse(os.path.exists(os.path.join(self.tmp, "c.xml")))


if __name__ == "__main__":
    unittest.main()
