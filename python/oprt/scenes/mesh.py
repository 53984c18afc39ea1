"""The building blocks of the paper's scenes: meshes as oprt-scene/1 `generate` recipes with
their triangle counts (the closed formulas of model/scene/generate.h), vectors, objects and
materials, the scene writer, and the camera's view for checking that things stay in the picture."""
import json
import math

#: The paper's scenes: 60 frames, 32 objects each.
FRAMES = 60
OBJECTS = 32


def r4(x):
    """Round for the file: 4 decimals, and no '-0.0'."""
    v = round(float(x), 4)
    return 0.0 if v == 0 else v


def v3(v):
    return [r4(c) for c in v]


# --- meshes: JSON recipe + triangle count from the closed formulas in generate.h ----------------

class Mesh:
    def __init__(self, spec, n):
        self.spec, self.n = spec, n

    def at(self, translate=None, rotate=None, scale=None, matrix=None):
        """This mesh placed inside its object (a part, or the mesh's own local transform)."""
        t = {}
        if matrix is not None:
            t["matrix"] = [r4(x) for row in matrix for x in row]
        else:
            if translate is not None:
                t["translate"] = v3(translate)
            if rotate is not None:
                axis, deg = rotate
                t["rotate"] = {"axis": v3(axis), "deg": r4(deg)}
            if scale is not None:
                t["scale"] = r4(scale)
        if "transform" in self.spec:  # already placed: place the placed mesh (outer after inner)
            return Mesh({"parts": [self.spec], "transform": t}, self.n)
        spec = dict(self.spec)
        spec["transform"] = t
        return Mesh(spec, self.n)


def gen(**kw):
    return {"generate": kw}


def box(sx, sy, sz, divisions=1):
    return Mesh(gen(kind="box", size=v3((sx, sy, sz)), divisions=divisions), 12 * divisions * divisions)


def sphere(radius, segments, rings):
    return Mesh(gen(kind="sphere", radius=r4(radius), segments=segments, rings=rings), 2 * segments * (rings - 1))


def cylinder(radius, height, segments, caps):
    return Mesh(gen(kind="cylinder", radius=r4(radius), height=r4(height), segments=segments, caps=caps),
                2 * segments + (2 * segments if caps else 0))


def torus(major, minor, segments, sides):
    return Mesh(gen(kind="torus", major=r4(major), minor=r4(minor), segments=segments, sides=sides),
                2 * segments * sides)


def plane(width, depth, nx=1, nz=1):
    return Mesh(gen(kind="plane", width=r4(width), depth=r4(depth), nx=nx, nz=nz), 2 * nx * nz)


def lathe(profile, segments, cap_first=False, cap_last=False):
    assert all(r > 0 for r, _ in profile) and len(profile) >= 2
    spec = gen(kind="lathe", profile=[[r4(r), r4(y)] for r, y in profile], segments=segments)
    if cap_first:
        spec["generate"]["cap_first"] = True
    if cap_last:
        spec["generate"]["cap_last"] = True
    return Mesh(spec, 2 * segments * (len(profile) - 1) + segments * (int(cap_first) + int(cap_last)))


def cloud(count, radius, size, seed):
    assert size < radius
    return Mesh(gen(kind="triangle_cloud", count=count, radius=r4(radius), size=r4(size), seed=seed), count)


def parts(*ms):
    return Mesh({"parts": [m.spec for m in ms]}, sum(m.n for m in ms))


def quad(centre, u, v):
    """A flat rectangle (2 triangles) from its centre and its two full edge vectors u and v."""
    n = cross(u, v)
    ln = math.sqrt(dot(n, n))
    n = [c / ln for c in n]
    # plane(1, 1) spans local x and z in [-0.5, 0.5] and faces +y: map x -> u, y -> n, z -> v.
    m = [[u[i], n[i], v[i], centre[i]] for i in range(3)]
    return plane(1, 1).at(matrix=m)


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


# --- scene assembly -----------------------------------------------------------------------------

def obj(name, material, mesh, translate=None, rotate=None, keys=None):
    o = {"name": name, "material": material, "mesh": mesh.spec}
    if translate is not None or rotate is not None:
        t = {}
        if translate is not None:
            t["translate"] = v3(translate)
        if rotate is not None:
            t["rotate"] = {"axis": v3(rotate[0]), "deg": r4(rotate[1])}
        o["transform"] = t
    if keys is not None:
        o["animation"] = {"keyframes": [
            {"frame": f, "translate": v3(tr), "rotate": {"axis": v3(ax), "deg": r4(deg)}} for f, tr, ax, deg in keys]}
    o["_n"] = mesh.n
    return o


def mat(diffuse, specular=(0.15, 0.15, 0.15), shininess=24):
    return {"diffuse": v3(diffuse), "specular": v3(specular), "shininess": shininess}


def paper_scene(comment, camera, background, ambient, lights, materials, objects):
    """An oprt-scene/1 document as the paper's scenes are: 256x256 pixels, FRAMES frames."""
    return {"format": "oprt-scene/1", "comment": comment, "camera": camera, "image": {"width": 256, "height": 256},
            "background": background, "ambient": ambient, "frames": FRAMES, "lights": lights,
            "materials": materials, "objects": objects}


def write_scene(path, scene):
    """One line per light, material and object: small diffs, readable, moderate size."""
    def one(x):
        return json.dumps(x, separators=(", ", ": "))
    lines = ["{"]
    head = ["format", "comment", "camera", "image", "background", "ambient", "frames"]
    for k in head:
        if k in scene:
            lines.append(f'  "{k}": {one(scene[k])},')
    lines.append('  "lights": [')
    lines.append(",\n".join("    " + one(l) for l in scene["lights"]))
    lines.append("  ],")
    lines.append('  "materials": {')
    lines.append(",\n".join(f"    {one(k)}: {one(v)}" for k, v in scene["materials"].items()))
    lines.append("  },")
    lines.append('  "objects": [')
    lines.append(",\n".join("    " + one({k: v for k, v in o.items() if k != "_n"}) for o in scene["objects"]))
    lines.append("  ]")
    lines.append("}")
    text = "\n".join(lines) + "\n"
    json.loads(text)  # well-formed
    with open(path, "w") as f:
        f.write(text)
    return len(text)


class View:
    """The pinhole camera of the scene format, for checking that things stay in the picture."""

    def __init__(self, eye, target, up, fov_y_deg, aspect=1.0):
        self.eye = eye
        f = [t - e for t, e in zip(target, eye)]
        self.fwd = [c / math.sqrt(dot(f, f)) for c in f]
        r = cross(self.fwd, up)
        self.right = [c / math.sqrt(dot(r, r)) for c in r]
        self.up = cross(self.right, self.fwd)
        self.ty = math.tan(math.radians(fov_y_deg) / 2)
        self.tx = self.ty * aspect

    def margin(self, centre, radius):
        """Smallest distance by which a ball stays inside the four side planes (>0: inside)."""
        p = [c - e for c, e in zip(centre, self.eye)]
        z, x, y = dot(p, self.fwd), dot(p, self.right), dot(p, self.up)
        out = []
        for t, s in ((self.tx, x), (self.ty, y)):
            norm = math.sqrt(1 + t * t)
            out.append((t * z - abs(s)) / norm - radius)  # distance to the side plane, minus radius
        return min(out + [z - radius])


def lerp(a, b, t):
    return [x + (y - x) * t for x, y in zip(a, b)]
