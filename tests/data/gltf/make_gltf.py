#!/usr/bin/env python3
"""Writes the glTF test files beside this script (their output is committed; rerun after a change).

hierarchy.gltf  the test scene, its buffer embedded as a base64 data URI
hierarchy.glb   the same scene as binary glTF (buffer 0 in the BIN chunk)
skin.gltf       hierarchy + a skin            -> must be refused at /skins/0
morph.gltf      hierarchy + a morph target    -> must be refused at /meshes/1/primitives/0/targets
animated.gltf   a BoxAnimated-like scene without a camera, every sampler kind, a moving light
camera_rig.gltf animated.gltf + a camera on an animated node
box_animated.gltf  the node tree and animations of Khronos' BoxAnimated sample (two boxes instead of
                its meshes): the inner box rises 2.52 above the outer one, out of the frame-0 bounds

The scene (world positions in tests/scene/gltf_test.cpp are computed by hand from this):
- node 0 "root": T (1,0,0), R 90 deg about Z, S 2; children 1 and 2
  - node 1 "box": mesh 0 (unit cube, three primitives: +-X red, +-Y blue, +-Z red), T (0,1,0)
  - node 2 "tri": mesh 1 (one non-indexed triangle + a LINES primitive), matrix S (0.5,1,1) then T (0,0,-3)
- node 3 "spinner": mesh 1; LINEAR translation (0,-2,0) -> (2,-2,0) -> (2,-2,0) and LINEAR rotation
  identity -> 90 deg about Y -> 180 deg about Y written as (0,-1,0,0) (the short way is 135 deg at 1.5 s),
  keys at 0, 1, 2 s
- node 4 "stepper": mesh 1; STEP translation (3,0,0), (3,1,0), (3,2,0) at 0, 0.5, 1 s
- node 5 "cubic": mesh 1; CUBICSPLINE translation, keys at 0 and 1 s: value (-1,2,0) out-tangent (3,0,0),
  value (0,2,0) in-tangent 0: x(0.5 s) = -0.5 + 0.125 * 3 = -0.125
- node 6 "camera": perspective yfov 0.8 rad, aspect 1.5; T (2,3,12), R -10 deg about X
- node 7 "lamp": KHR point light, colour (1,0.5,0.5), intensity 20, T (3,5,4)
- node 8 "spot": KHR spot light, white, intensity 10, T (-3,5,4)
"""
import base64
import json
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def build():
    data = bytearray()
    views, accessors = [], []

    def add(fmt, values, ctype, atype, count, minmax=None):
        while len(data) % 4:
            data.append(0)
        offset = len(data)
        data.extend(struct.pack("<" + fmt * len(values), *values))
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(data) - offset})
        acc = {"bufferView": len(views) - 1, "componentType": ctype, "type": atype, "count": count}
        if minmax:
            acc["min"], acc["max"] = minmax
        accessors.append(acc)
        return len(accessors) - 1

    F, US = 5126, 5123
    box = [c for i in range(8) for c in (0.5 if i & 1 else -0.5, 0.5 if i & 2 else -0.5, 0.5 if i & 4 else -0.5)]
    a_box = add("f", box, F, "VEC3", 8, ([-0.5] * 3, [0.5] * 3))
    a_x = add("H", [1, 3, 7, 1, 7, 5, 0, 4, 6, 0, 6, 2], US, "SCALAR", 12)
    a_y = add("H", [2, 6, 7, 2, 7, 3, 0, 1, 5, 0, 5, 4], US, "SCALAR", 12)
    a_z = add("H", [4, 5, 7, 4, 7, 6, 0, 2, 3, 0, 3, 1], US, "SCALAR", 12)
    a_tri = add("f", [0, 0, 0, 1, 0, 0, 0, 1, 0], F, "VEC3", 3, ([0, 0, 0], [1, 1, 0]))
    a_line = add("f", [0, 0, 0, 0, 0, 1], F, "VEC3", 2, ([0, 0, 0], [0, 0, 1]))
    s45 = math.sqrt(0.5)
    a_t3 = add("f", [0, 1, 2], F, "SCALAR", 3, ([0], [2]))
    a_spin_t = add("f", [0, -2, 0, 2, -2, 0, 2, -2, 0], F, "VEC3", 3)
    a_spin_r = add("f", [0, 0, 0, 1, 0, s45, 0, s45, 0, -1, 0, 0], F, "VEC4", 3)
    a_step_in = add("f", [0, 0.5, 1], F, "SCALAR", 3, ([0], [1]))
    a_step_t = add("f", [3, 0, 0, 3, 1, 0, 3, 2, 0], F, "VEC3", 3)
    a_cub_in = add("f", [0, 1], F, "SCALAR", 2, ([0], [1]))
    a_cub_t = add("f", [0, 0, 0, -1, 2, 0, 3, 0, 0, 0, 0, 0, 0, 2, 0, 0, 0, 0], F, "VEC3", 6)

    def quat(axis, deg):
        h = math.radians(deg) / 2
        return [axis[0] * math.sin(h), axis[1] * math.sin(h), axis[2] * math.sin(h), math.cos(h)]

    doc = {
        "asset": {"version": "2.0", "generator": "oprt tests/data/gltf/make_gltf.py"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "scene": 0,
        "scenes": [{"nodes": [0, 3, 4, 5, 6, 7, 8]}],
        "nodes": [
            {"name": "root", "translation": [1, 0, 0], "rotation": quat([0, 0, 1], 90), "scale": [2, 2, 2],
             "children": [1, 2]},
            {"name": "box", "mesh": 0, "translation": [0, 1, 0]},
            {"name": "tri", "mesh": 1, "matrix": [0.5, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -3, 1]},
            {"name": "spinner", "mesh": 1},
            {"name": "stepper", "mesh": 1},
            {"name": "cubic", "mesh": 1},
            {"name": "camera", "camera": 0, "translation": [2, 3, 12], "rotation": quat([1, 0, 0], -10)},
            {"name": "lamp", "translation": [3, 5, 4], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"name": "spot", "translation": [-3, 5, 4], "extensions": {"KHR_lights_punctual": {"light": 1}}},
        ],
        "meshes": [
            {"name": "cube", "primitives": [
                {"attributes": {"POSITION": a_box}, "indices": a_x, "material": 0},
                {"attributes": {"POSITION": a_box}, "indices": a_y, "material": 1},
                {"attributes": {"POSITION": a_box}, "indices": a_z, "material": 0}]},
            {"name": "triangle", "primitives": [
                {"attributes": {"POSITION": a_tri}},
                {"attributes": {"POSITION": a_line}, "mode": 1}]},
        ],
        "materials": [
            {"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.1, 0.1, 1],
                                                     "metallicFactor": 0, "roughnessFactor": 0.5}},
            {"name": "blue", "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.2, 0.9, 1],
                                                      "metallicFactor": 1, "roughnessFactor": 0.3}},
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "aspectRatio": 1.5, "znear": 0.1}}],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1, 0.5, 0.5], "intensity": 20},
            {"type": "spot", "intensity": 10, "spot": {"outerConeAngle": 0.7}}]}},
        "animations": [
            {"name": "spin", "samplers": [
                {"input": a_t3, "output": a_spin_t, "interpolation": "LINEAR"},
                {"input": a_t3, "output": a_spin_r}],
             "channels": [
                {"sampler": 0, "target": {"node": 3, "path": "translation"}},
                {"sampler": 1, "target": {"node": 3, "path": "rotation"}}]},
            {"name": "step and cubic", "samplers": [
                {"input": a_step_in, "output": a_step_t, "interpolation": "STEP"},
                {"input": a_cub_in, "output": a_cub_t, "interpolation": "CUBICSPLINE"}],
             "channels": [
                {"sampler": 0, "target": {"node": 4, "path": "translation"}},
                {"sampler": 1, "target": {"node": 5, "path": "translation"}}]},
        ],
        "bufferViews": views,
        "accessors": accessors,
    }
    while len(data) % 4:
        data.append(0)
    return doc, bytes(data)


def build_animated(with_camera):
    """animated.gltf (world positions in tests/scene/gltf_test.cpp are computed by hand from this):

    Three animations, one per sampler kind, all playing at once; the last key is at 2 s, so the
    scene has frames 0..60 (30 per second). No camera unless with_camera.
    - node 0 "floor": the unit cube (corners +-0.5), static
    - node 1 "lift": LINEAR translation (0,0,0) at 0 s -> (0,6,0) at 2 s (y = 3 t); children 2, 3
      - node 2 "cube": the unit cube, T (0,1,0); STEP scale 1 at 0 s, 2 at 1 s. Its corner
        (0.5,0.5,0.5) is at (0.5,1.5,0.5) at frame 0, (1,5,1) at frame 30, (1,8,1) at frame 60:
        it rises far above the frame-0 bounds (y <= 1.5), as Khronos' BoxAnimated's inner box does
      - node 3 "lamp": KHR point light, T (0,2,0): at (0, 2 + 3 t, 0); LINEAR rotation about Y from
        0 at 0 s to 90 degrees at 2 s, which turns its -Z (a directional light's direction) to -X
    with_camera adds, as scene roots:
    - node 4 "rig": CUBICSPLINE translation, keys at 0 s (0,0,20) and 2 s (10,0,20), all tangents
      zero: x = 10 (3 s^2 - 2 s^3), s = t / 2 (5 at 1 s); child 5
      - node 5 "eye": perspective camera (yfov 0.7), T (0,2,0): the eye at (x, 2, 20), looking -Z
    """
    data = bytearray()
    views, accessors = [], []

    def add(fmt, values, ctype, atype, count, minmax=None):
        while len(data) % 4:
            data.append(0)
        offset = len(data)
        data.extend(struct.pack("<" + fmt * len(values), *values))
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(data) - offset})
        acc = {"bufferView": len(views) - 1, "componentType": ctype, "type": atype, "count": count}
        if minmax:
            acc["min"], acc["max"] = minmax
        accessors.append(acc)
        return len(accessors) - 1

    F, US = 5126, 5123
    box = [c for i in range(8) for c in (0.5 if i & 1 else -0.5, 0.5 if i & 2 else -0.5, 0.5 if i & 4 else -0.5)]
    a_box = add("f", box, F, "VEC3", 8, ([-0.5] * 3, [0.5] * 3))
    a_idx = add("H", [1, 3, 7, 1, 7, 5, 0, 4, 6, 0, 6, 2, 2, 6, 7, 2, 7, 3, 0, 1, 5, 0, 5, 4,
                      4, 5, 7, 4, 7, 6, 0, 2, 3, 0, 3, 1], US, "SCALAR", 36)
    a_t2 = add("f", [0, 2], F, "SCALAR", 2, ([0], [2]))
    a_lift = add("f", [0, 0, 0, 0, 6, 0], F, "VEC3", 2)
    a_t1 = add("f", [0, 1], F, "SCALAR", 2, ([0], [1]))
    a_scale = add("f", [1, 1, 1, 2, 2, 2], F, "VEC3", 2)
    a_rig = add("f", [0, 0, 0, 0, 0, 20, 0, 0, 0, 0, 0, 0, 10, 0, 20, 0, 0, 0], F, "VEC3", 6)
    s45 = math.sqrt(0.5)
    a_turn = add("f", [0, 0, 0, 1, 0, s45, 0, s45], F, "VEC4", 2)
    doc = {
        "asset": {"version": "2.0", "generator": "oprt tests/data/gltf/make_gltf.py"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1] + ([4] if with_camera else [])}],
        "nodes": [
            {"name": "floor", "mesh": 0},
            {"name": "lift", "children": [2, 3]},
            {"name": "cube", "mesh": 0, "translation": [0, 1, 0]},
            {"name": "lamp", "translation": [0, 2, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
        ],
        "meshes": [{"name": "cube", "primitives": [{"attributes": {"POSITION": a_box}, "indices": a_idx}]}],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 5}]}},
        "animations": [
            {"name": "lift", "samplers": [{"input": a_t2, "output": a_lift, "interpolation": "LINEAR"}],
             "channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}}]},
            {"name": "grow", "samplers": [{"input": a_t1, "output": a_scale, "interpolation": "STEP"}],
             "channels": [{"sampler": 0, "target": {"node": 2, "path": "scale"}}]},
            {"name": "turn", "samplers": [{"input": a_t2, "output": a_turn}],
             "channels": [{"sampler": 0, "target": {"node": 3, "path": "rotation"}}]},
        ],
        "bufferViews": views,
        "accessors": accessors,
    }
    if with_camera:
        doc["nodes"] += [{"name": "rig", "children": [5]},
                         {"name": "eye", "camera": 0, "translation": [0, 2, 0]}]
        doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1}}]
        doc["animations"].append(
            {"name": "dolly", "samplers": [{"input": a_t2, "output": a_rig, "interpolation": "CUBICSPLINE"}],
             "channels": [{"sampler": 0, "target": {"node": 4, "path": "translation"}}]})
    while len(data) % 4:
        data.append(0)
    return doc, bytes(data)


def build_box_animated():
    """As Khronos' glTF-Sample-Models 2.0/BoxAnimated: nodes 0 (rotation (-0,-0,-0,-1), child 1)
    -> 1 (child 2) -> 2 (mesh 0, the inner box, rotation (-0,-0,-0,-1)), and node 3 (mesh 1, the
    outer box); animation 0 turns node 2 LINEAR from (-0,-0,-0,-1) at 1.25 s to (1,0,0,4.49e-11)
    at 2.5 s, animation 1 moves node 0 LINEAR through y = 0, 2.52, 2.52, 0 at 0, 1.25, 2.5, 3.708 s.
    The meshes are boxes of the sample's bounds: inner +-(0.335, 0.5, 0.335), outer +-0.5."""
    data = bytearray()
    views, accessors = [], []

    def add(fmt, values, ctype, atype, count):
        while len(data) % 4:
            data.append(0)
        offset = len(data)
        data.extend(struct.pack("<" + fmt * len(values), *values))
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(data) - offset})
        accessors.append({"bufferView": len(views) - 1, "componentType": ctype, "type": atype, "count": count})
        return len(accessors) - 1

    def box(hx, hy, hz):
        return [c for i in range(8) for c in (hx if i & 1 else -hx, hy if i & 2 else -hy, hz if i & 4 else -hz)]

    F, US = 5126, 5123
    idx = [1, 3, 7, 1, 7, 5, 0, 4, 6, 0, 6, 2, 2, 6, 7, 2, 7, 3, 0, 1, 5, 0, 5, 4, 4, 5, 7, 4, 7, 6, 0, 2, 3, 0, 3, 1]
    a_idx = add("H", idx, US, "SCALAR", 36)
    a_inner = add("f", box(0.33504, 0.5, 0.33504), F, "VEC3", 8)
    a_outer = add("f", box(0.5, 0.5, 0.5), F, "VEC3", 8)
    a_rot_t = add("f", [1.25, 2.5], F, "SCALAR", 2)
    a_rot = add("f", [-0.0, -0.0, -0.0, -1.0, 1.0, 0.0, 0.0, 4.4896593387466768e-11], F, "VEC4", 2)
    a_tr_t = add("f", [0, 1.25, 2.5, 3.708329916000366], F, "SCALAR", 4)
    a_tr = add("f", [0, 0, 0, 0, 2.52, 0, 0, 2.52, 0, 0, 0, 0], F, "VEC3", 4)
    doc = {
        "asset": {"version": "2.0", "generator": "oprt tests/data/gltf/make_gltf.py (after BoxAnimated)"},
        "scene": 0,
        "scenes": [{"nodes": [3, 0]}],
        "nodes": [
            {"children": [1], "rotation": [-0.0, -0.0, -0.0, -1.0]},
            {"children": [2]},
            {"mesh": 0, "rotation": [-0.0, -0.0, -0.0, -1.0]},
            {"mesh": 1},
        ],
        "meshes": [
            {"name": "inner_box", "primitives": [{"attributes": {"POSITION": a_inner}, "indices": a_idx, "material": 0}]},
            {"name": "outer_box", "primitives": [{"attributes": {"POSITION": a_outer}, "indices": a_idx, "material": 1}]},
        ],
        "animations": [
            {"channels": [{"sampler": 0, "target": {"node": 2, "path": "rotation"}}],
             "samplers": [{"input": a_rot_t, "interpolation": "LINEAR", "output": a_rot}]},
            {"channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}],
             "samplers": [{"input": a_tr_t, "interpolation": "LINEAR", "output": a_tr}]},
        ],
        "materials": [
            {"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.416, 0.795, 1.0], "metallicFactor": 0.0},
             "name": "inner"},
            {"pbrMetallicRoughness": {"baseColorFactor": [0.302, 0.534, 0.8, 1.0], "metallicFactor": 0.0},
             "name": "outer"},
        ],
        "bufferViews": views,
        "accessors": accessors,
    }
    while len(data) % 4:
        data.append(0)
    return doc, bytes(data)


def write_gltf(name, doc, data):
    doc = json.loads(json.dumps(doc))
    doc["buffers"] = [{"byteLength": len(data),
                       "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}]
    with open(os.path.join(HERE, name), "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


def write_glb(name, doc, data):
    doc = json.loads(json.dumps(doc))
    doc["buffers"] = [{"byteLength": len(data)}]
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    out = struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(text) + 8 + len(data))
    out += struct.pack("<II", len(text), 0x4E4F534A) + text
    out += struct.pack("<II", len(data), 0x004E4942) + data
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(out)


def main():
    doc, data = build()
    write_gltf("hierarchy.gltf", doc, data)
    write_glb("hierarchy.glb", doc, data)
    skin = json.loads(json.dumps(doc))
    skin["skins"] = [{"joints": [1]}]
    skin["nodes"][2]["skin"] = 0
    write_gltf("skin.gltf", skin, data)
    morph = json.loads(json.dumps(doc))
    morph["meshes"][1]["primitives"][0]["targets"] = [{"POSITION": 4}]
    write_gltf("morph.gltf", morph, data)
    write_gltf("animated.gltf", *build_animated(False))
    write_gltf("camera_rig.gltf", *build_animated(True))
    write_gltf("box_animated.gltf", *build_box_animated())


if __name__ == "__main__":
    main()
