#!/usr/bin/env python3
"""Tests of bench/mitsuba_peer.py's conversion (no Mitsuba needed):

    python3 -m unittest discover -s bench -p 'test_mitsuba_peer.py' -v
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
        b = self.bsdf_of(conv, plys[0])["bsdf"]
        self.assertTrue(close(b["reflectance"]["value"], [0.4, 0.5, 0.6]))
        self.assertEqual(self.bsdf_of(conv, plys[3])["bsdf"]["reflectance"]["value"], [0.5, 0.5, 0.5])
        conv = self.convert(doc, instancing=True)
        groups = self.shapes(conv, "shapegroup")
        inst = self.shapes(conv, "instance")
        self.assertEqual((len(groups), len(inst), len(self.shapes(conv, "ply"))), (1, 3, 1))
        self.assertTrue(close(mp.mat_point(inst[2]["to_world"]["__transform__"], [0, 0, 0]), [2, 0, 0]))


class PassPlanTest(unittest.TestCase):
    def test_plans(self):
        self.assertEqual(mp.pass_plan(1920, 1080, 300, "symbolic", 2 ** 26, "auto"), [300])
        plan = mp.pass_plan(1920, 1080, 300, "evaluated", 2 ** 26, "auto")
        self.assertEqual(sum(plan), 300)
        self.assertTrue(all(1920 * 1080 * p <= 2 ** 26 for p in plan))
        self.assertEqual(mp.pass_plan(10, 10, 7, "symbolic", 2 ** 26, "3"), [3, 2, 2])


class EmittedPluginsTest(Base):
    def test_every_emitted_plugin_is_listed(self):
        # scripts/peer-pack.sh keeps EMITTED_PLUGINS: every scene must stay inside it.
        for name in ("seed57", "rtiow-cover", "cornell-box", "glossy-lights", "quick", "sky-sun", "divergent"):
            conv = mp.convert(os.path.join(ROOT, "scenes", name + ".json"))
            extra = set(conv.plugins()) - set(mp.EMITTED_PLUGINS) - set(mp.PYTHON_PLUGINS)
            self.assertEqual(extra, set(), name)


if __name__ == "__main__":
    unittest.main()
