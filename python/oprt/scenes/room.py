"""Paper scene (b) 'room' (Kaeriyama et al., Fig. 5): an indoor room, 35,108 triangles in 32
rigid objects of very unequal size and primitive count, a few of them animated."""
import math
import random

from .mesh import FRAMES, OBJECTS, box, cloud, cross, cylinder, lathe, lerp, mat, obj, paper_scene, parts, plane, \
    quad, sphere, torus

ROOM_TRIANGLES = 35108


W, D, H = 6.0, 7.0, 2.8           # room: x in [-3, 3], z in [-3.5, 3.5], y in [0, 2.8]
X0, X1, Z0, Z1 = -W / 2, W / 2, -D / 2, D / 2
DOOR_Z0, DOOR_Z1, DOOR_H = -1.6, -0.7, 2.05   # doorway in the left wall (x = X0)
ALCOVE = 0.8                                  # depth of the dim hall behind the doorway


def vase_profile(n):
    pts = []
    for i in range(n):
        t = i / (n - 1)
        r = 0.045 + 0.07 * math.sin(math.pi * min(t / 0.78, 1.0)) ** 1.4 + 0.03 * max(0.0, (t - 0.78) / 0.22) ** 2
        pts.append((r, 0.36 * t))
    return pts


def bowl_profile(n, radius):
    pts = []
    for i in range(n):
        a = 0.35 + (math.pi / 2 - 0.35) * i / (n - 1)
        pts.append((radius * math.sin(a), radius * (1 - math.cos(a)) * 0.75))
    return pts


def chair():
    legs = [box(0.035, 0.45, 0.035).at(translate=(sx * 0.19, 0.225, sz * 0.19)) for sx in (-1, 1) for sz in (-1, 1)]
    posts = [box(0.035, 0.5, 0.035).at(translate=(sx * 0.19, 0.72, -0.19)) for sx in (-1, 1)]
    return parts(box(0.46, 0.04, 0.46).at(translate=(0, 0.47, 0)), *legs, *posts,
                 box(0.42, 0.18, 0.03).at(translate=(0, 0.86, -0.19)))


def books(rng, shelves, width):
    """Upright books along the given shelf heights, filling most of `width`."""
    ms = []
    for y in shelves:
        x = -width / 2 + 0.03
        while True:
            t = rng.uniform(0.025, 0.055)
            if x + t > width / 2 - 0.05:
                break
            if rng.random() < 0.08:       # a gap now and then
                x += rng.uniform(0.04, 0.12)
                continue
            h, d = rng.uniform(0.2, 0.32), rng.uniform(0.18, 0.25)
            ms.append(box(t, h, d).at(translate=(x + t / 2, y + h / 2, 0.02)))
            x += t + 0.003
    return parts(*ms)


def room_materials():
    """The room's materials by name."""
    return {
        "floor": mat((0.55, 0.38, 0.22), (0.1, 0.1, 0.1), 16),
        "ceiling": mat((0.9, 0.9, 0.88), (0, 0, 0), 1),
        "wall": mat((0.82, 0.78, 0.66), (0.02, 0.02, 0.02), 4),
        "wall_accent": mat((0.45, 0.6, 0.62), (0.02, 0.02, 0.02), 4),
        "door": mat((0.42, 0.26, 0.14), (0.2, 0.2, 0.2), 32),
        "table_wood": mat((0.6, 0.4, 0.22), (0.3, 0.3, 0.3), 40),
        "chair": mat((0.3, 0.22, 0.16), (0.2, 0.2, 0.2), 24),
        "vase": mat((0.15, 0.3, 0.75), (0.7, 0.7, 0.7), 80),
        "ceramic": mat((0.92, 0.9, 0.85), (0.6, 0.6, 0.6), 60),
        "fruit": mat((0.95, 0.5, 0.08), (0.4, 0.4, 0.3), 40),
        "shelf": mat((0.7, 0.55, 0.38), (0.1, 0.1, 0.1), 16),
        "books_red": mat((0.7, 0.12, 0.1)),
        "books_green": mat((0.15, 0.45, 0.25)),
        "sideboard": mat((0.2, 0.32, 0.35), (0.3, 0.3, 0.3), 32),
        "globe": mat((0.2, 0.45, 0.7), (0.5, 0.5, 0.5), 60),
        "picture": mat((0.85, 0.65, 0.15), (0.1, 0.1, 0.1), 16),
        "window_frame": mat((0.95, 0.95, 0.95), (0.2, 0.2, 0.2), 32),
        "sky": mat((0.6, 0.8, 1.0), (0, 0, 0), 1),
        "sofa": mat((0.55, 0.12, 0.2), (0.05, 0.05, 0.05), 8),
        "metal": mat((0.25, 0.25, 0.27), (0.8, 0.8, 0.8), 64),
        "gold": mat((0.85, 0.65, 0.2), (0.9, 0.8, 0.5), 90),
        "rug": mat((0.35, 0.3, 0.55), (0, 0, 0), 1),
        "lamp": mat((0.95, 0.9, 0.75), (0.2, 0.2, 0.2), 16),
        "fan": mat((0.35, 0.25, 0.18), (0.3, 0.3, 0.3), 32),
        "ball": mat((0.9, 0.15, 0.1), (0.6, 0.6, 0.6), 60),
        "pot": mat((0.75, 0.38, 0.22), (0.1, 0.1, 0.1), 12),
        "leaves": mat((0.2, 0.55, 0.15), (0.05, 0.1, 0.05), 8),
    }


def room_shell(o):
    """Floor, ceiling, walls, the doorway's alcove and the swinging door."""
    # Shell: large, two triangles each (the left wall has a doorway opening into a dim alcove).
    o.append(obj("floor", "floor", plane(W, D)))
    o.append(obj("ceiling", "ceiling", plane(W, D).at(translate=(0, H, 0))))
    o.append(obj("wall_back", "wall", quad((0, H / 2, Z0), (W, 0, 0), (0, H, 0))))
    o.append(obj("wall_front", "wall", quad((0, H / 2, Z1), (W, 0, 0), (0, H, 0))))
    o.append(obj("wall_right", "wall_accent", quad((X1, H / 2, 0), (0, 0, D), (0, H, 0))))
    dz = DOOR_Z1 - DOOR_Z0
    o.append(obj("wall_left", "wall", parts(
        quad((X0, H / 2, (Z0 + DOOR_Z0) / 2), (0, 0, DOOR_Z0 - Z0), (0, H, 0)),
        quad((X0, H / 2, (DOOR_Z1 + Z1) / 2), (0, 0, Z1 - DOOR_Z1), (0, H, 0)),
        quad((X0, (DOOR_H + H) / 2, (DOOR_Z0 + DOOR_Z1) / 2), (0, 0, dz), (0, H - DOOR_H, 0)),
        # the alcove behind the doorway: far wall, two sides, top, floor
        quad((X0 - ALCOVE, DOOR_H / 2, (DOOR_Z0 + DOOR_Z1) / 2), (0, 0, dz), (0, DOOR_H, 0)),
        quad((X0 - ALCOVE / 2, DOOR_H / 2, DOOR_Z0), (ALCOVE, 0, 0), (0, DOOR_H, 0)),
        quad((X0 - ALCOVE / 2, DOOR_H / 2, DOOR_Z1), (ALCOVE, 0, 0), (0, DOOR_H, 0)),
        quad((X0 - ALCOVE / 2, DOOR_H, (DOOR_Z0 + DOOR_Z1) / 2), (ALCOVE, 0, 0), (0, 0, dz)),
        quad((X0 - ALCOVE / 2, 0, (DOOR_Z0 + DOOR_Z1) / 2), (ALCOVE, 0, 0), (0, 0, dz)))))
    # The door: hinged at (X0, DOOR_Z0), closed along +z, swings into the room (towards +x).
    door = parts(box(0.04, DOOR_H - 0.02, dz - 0.02).at(translate=(0.02, (DOOR_H - 0.02) / 2, dz / 2)),
                 cylinder(0.018, 0.08, 10, True).at(translate=(0.04, 1.0, dz - 0.1), rotate=((0, 0, 1), -90)),
                 box(0.02, 0.02, 0.12).at(translate=(0.12, 1.0, dz - 0.15)))
    hinge = (X0, 0, DOOR_Z0)
    o.append(obj("door", "door", door, keys=[(0, hinge, (0, 1, 0), 0), (20, hinge, (0, 1, 0), 45),
                                             (35, hinge, (0, 1, 0), 80), (FRAMES - 1, hinge, (0, 1, 0), 30)]))


def room_table(o):
    """The dining table with chairs, vase, bowl and fruit; returns its place (x, z)."""
    # Dining table with four chairs, a vase, a fruit bowl and fruit.
    tx, tz, top = -0.2, -1.3, 0.79
    legs = [cylinder(0.035, top - 0.05, 12, False).at(translate=(sx * 0.7, 0, sz * 0.37))
            for sx in (-1, 1) for sz in (-1, 1)]
    o.append(obj("dining_table", "table_wood", parts(box(1.6, 0.05, 0.9).at(translate=(0, top - 0.025, 0)), *legs),
                 translate=(tx, 0, tz)))
    for i, (x, z, deg) in enumerate([(tx - 0.4, tz - 0.72, 0), (tx + 0.4, tz - 0.75, 8),
                                     (tx + 0.15, tz + 0.85, 195), (tx + 1.08, tz, -90)]):
        o.append(obj(f"chair_{i + 1}", "chair", chair(), translate=(x, 0, z), rotate=((0, 1, 0), deg)))
    o.append(obj("vase", "vase", lathe(vase_profile(41), 96, cap_first=True), translate=(tx - 0.4, top, tz + 0.05)))
    o.append(obj("fruit_bowl", "ceramic", lathe(bowl_profile(12, 0.16), 48, cap_first=True),
                 translate=(tx + 0.3, top, tz + 0.05)))
    fruit = [sphere(0.045, 16, 8).at(translate=(x, 0.05, z))
             for x, z in ((-0.05, 0.0), (0.05, 0.03), (0.0, -0.06), (0.02, 0.07), (-0.06, 0.09))]
    o.append(obj("fruit", "fruit", parts(*fruit), translate=(tx + 0.3, top, tz + 0.05)))
    return tx, tz


def room_back_wall(o, rng):
    """Bookshelf and books, sideboard and globe, picture and window."""
    # Back wall: bookshelf with books, a sideboard with a globe, a picture above it.
    sw, sh, sd = 1.2, 2.0, 0.35
    shelf_y = [0.06, 0.5, 0.94, 1.38, 1.82]
    o.append(obj("bookshelf", "shelf", parts(
        *[box(0.03, sh, sd).at(translate=(sx * (sw / 2 - 0.015), sh / 2, 0)) for sx in (-1, 1)],
        *[box(sw - 0.06, 0.03, sd).at(translate=(0, y - 0.015, 0)) for y in shelf_y + [sh]],
        box(sw, sh, 0.01).at(translate=(0, sh / 2, -sd / 2 + 0.005))), translate=(-2.1, 0, Z0 + sd / 2)))
    o.append(obj("books_red", "books_red", books(rng, shelf_y[0::2], sw - 0.06), translate=(-2.1, 0, Z0 + sd / 2)))
    o.append(obj("books_green", "books_green", books(rng, shelf_y[1::2], sw - 0.06), translate=(-2.1, 0, Z0 + sd / 2)))
    bw, bh, bd = 1.8, 0.75, 0.45
    o.append(obj("sideboard", "sideboard", parts(
        box(bw, bh - 0.1, bd).at(translate=(0, 0.1 + (bh - 0.1) / 2, 0)),
        box(bw + 0.04, 0.03, bd + 0.03).at(translate=(0, bh + 0.015, 0)),
        *[box(0.04, 0.1, 0.04).at(translate=(sx * (bw / 2 - 0.05), 0.05, sz * (bd / 2 - 0.05)))
          for sx in (-1, 1) for sz in (-1, 1)],
        *[box(0.56, 0.55, 0.01).at(translate=(x, 0.1 + (bh - 0.1) / 2, bd / 2 + 0.005)) for x in (-0.6, 0, 0.6)],
        *[box(0.12, 0.02, 0.03).at(translate=(x, 0.62, bd / 2 + 0.02)) for x in (-0.6, 0, 0.6)]),
        translate=(1.1, 0, Z0 + bd / 2 + 0.01)))
    o.append(obj("globe", "globe", parts(
        lathe([(0.11, 0.0), (0.11, 0.015), (0.06, 0.03)], 32, cap_first=True, cap_last=True),
        cylinder(0.012, 0.12, 8, False).at(translate=(0, 0.03, 0)),
        sphere(0.16, 72, 48).at(translate=(0, 0.32, 0)),
        torus(0.175, 0.007, 48, 6).at(translate=(0, 0.32, 0), rotate=((1, 0, 0.35), 90))),
        translate=(1.6, bh + 0.03, Z0 + 0.24)))
    pw, ph = 1.0, 0.7
    o.append(obj("picture", "picture", parts(
        box(pw, ph, 0.015).at(translate=(0, 0, 0.0075)),
        *[box(pw + 0.08, 0.04, 0.04).at(translate=(0, sy * (ph / 2 + 0.02), 0.02)) for sy in (-1, 1)],
        *[box(0.04, ph, 0.04).at(translate=(sx * (pw / 2 + 0.02), 0, 0.02)) for sx in (-1, 1)]),
        translate=(0.9, 1.65, Z0)))
    # Back wall, between shelf and sideboard: a window (frame and the sky behind it).
    wx, wy, ww, wh = -0.65, 1.5, 1.1, 1.2
    o.append(obj("window_frame", "window_frame", parts(
        *[box(ww + 0.12, 0.06, 0.08).at(translate=(0, sy * (wh / 2 + 0.03), 0)) for sy in (-1, 1)],
        *[box(0.06, wh, 0.08).at(translate=(sx * (ww / 2 + 0.03), 0, 0)) for sx in (-1, 1)],
        box(0.04, wh, 0.04).at(translate=(0, 0, 0.02)), box(ww, 0.04, 0.04).at(translate=(0, 0, 0.02)),
        box(ww + 0.2, 0.03, 0.2).at(translate=(0, -wh / 2 - 0.075, 0.08))),
        translate=(wx, wy, Z0 + 0.04)))
    o.append(obj("window_view", "sky", quad((wx, wy, Z0 + 0.005), (ww, 0, 0), (0, wh, 0))))


def room_living(o):
    """Sofa, coffee table with a sculpture, rug, floor lamp."""
    # Living corner: sofa against the left wall, round coffee table with a sculpture, rug.
    sofa = parts(box(2.0, 0.3, 0.9).at(translate=(0, 0.25, 0)),
                 *[box(0.92, 0.14, 0.68).at(translate=(sx * 0.47, 0.47, 0.1)) for sx in (-1, 1)],
                 box(2.0, 0.5, 0.22).at(translate=(0, 0.65, -0.34)),
                 *[box(0.16, 0.28, 0.9).at(translate=(sx * 1.0, 0.54, 0)) for sx in (-1, 1)],
                 *[box(0.05, 0.1, 0.05).at(translate=(sx * 0.95, 0.05, sz * 0.4)) for sx in (-1, 1) for sz in (-1, 1)])
    o.append(obj("sofa", "sofa", sofa, translate=(X0 + 0.47, 0, 0.45), rotate=((0, 1, 0), 90)))
    ctx, ctz = -1.45, 0.45
    o.append(obj("coffee_table", "table_wood", parts(
        cylinder(0.45, 0.04, 48, True).at(translate=(0, 0.38, 0)),
        cylinder(0.05, 0.36, 16, False).at(translate=(0, 0.02, 0)),
        lathe([(0.25, 0.0), (0.25, 0.02), (0.15, 0.03)], 32, cap_first=True, cap_last=True)),
        translate=(ctx, 0, ctz)))
    o.append(obj("sculpture", "gold", torus(0.12, 0.045, 96, 32).at(translate=(0, 0.165, 0), rotate=((1, 0, 0), 90)),
                 translate=(ctx, 0.42, ctz), rotate=((0, 1, 0), 30)))
    o.append(obj("rug", "rug", box(2.2, 0.01, 1.6), translate=(ctx + 0.1, 0.005, ctz)))
    # Floor lamp by the right wall.
    o.append(obj("floor_lamp", "lamp", parts(
        lathe([(0.16, 0.0), (0.16, 0.02), (0.05, 0.04)], 32, cap_first=True, cap_last=True),
        cylinder(0.014, 1.45, 12, False).at(translate=(0, 0.04, 0)),
        lathe([(0.24, 1.38), (0.22, 1.45), (0.19, 1.52), (0.16, 1.59), (0.14, 1.66)], 48)),
        translate=(2.5, 0, -1.7)))


def room_moving(o, tx, tz):
    """The ceiling fan above the table and the rolling ball (animated)."""
    # Ceiling fan above the table: 4 pitched blades on a motor, turning.
    blade = box(0.6, 0.012, 0.13).at(translate=(0.42, 0, 0), rotate=((1, 0, 0), 12))
    fan = parts(cylinder(0.015, 0.25, 10, False).at(translate=(0, -0.25, 0)),
                lathe([(0.05, -0.25), (0.1, -0.28), (0.11, -0.31), (0.09, -0.34), (0.05, -0.36)], 32,
                      cap_first=True, cap_last=True),
                *[blade.at(translate=(0, -0.3, 0), rotate=((0, 1, 0), 90 * k)) for k in range(4)])
    fan_at = (tx, H, tz)
    o.append(obj("ceiling_fan", "fan", fan,
                 keys=[(f, fan_at, (0, 1, 0), -9 * f) for f in range(0, FRAMES + 1, 5)]))
    # A ball rolling across the floor (slowing down), rotating as it rolls.
    br = 0.16
    start, end = (1.9, br, 0.55), (0.55, br, 0.75)
    dist = math.dist(start, end)
    roll_axis = cross((0, 1, 0), [e - s for s, e in zip(start, end)])  # rolling: axis = up x direction
    keys = []
    for f in range(0, FRAMES + 1, 4):
        s = 1 - (1 - f / FRAMES) ** 2
        keys.append((f, lerp(start, end, s), roll_axis, math.degrees(s * dist / br)))
    o.append(obj("ball", "ball", sphere(br, 32, 16), keys=keys))


def room():
    rng = random.Random(1978)
    materials = room_materials()
    o = []
    room_shell(o)
    tx, tz = room_table(o)
    room_back_wall(o, rng)
    room_living(o)
    room_moving(o, tx, tz)
    # Potted plant in the back-right corner: a dense bush of small leaves absorbs the remainder.
    px, pz = 2.45, Z0 + 0.55
    o.append(obj("plant_pot", "pot", lathe([(0.15, 0.0), (0.2, 0.36), (0.23, 0.38), (0.23, 0.43), (0.21, 0.43)], 48,
                                           cap_first=True), translate=(px, 0, pz)))
    rest = ROOM_TRIANGLES - sum(x["_n"] for x in o)
    assert 2000 < rest < 12000, rest
    o.append(obj("plant_leaves", "leaves", cloud(rest, 0.45, 0.07, 77), translate=(px, 0.43 + 0.4, pz)))

    assert len(o) == OBJECTS, len(o)
    assert sum(x["_n"] for x in o) == ROOM_TRIANGLES
    camera = {"eye": [1.7, 1.55, 3.35], "target": [0.17, 1.08, -0.86], "up": [0, 1, 0], "fov_y_deg": 62}
    return paper_scene("Paper scene (b) 'room': an indoor room, 35,108 triangles in 32 objects of very unequal size "
                       "and primitive count; door, ceiling fan and ball animated. Generated by scripts/make_paper_scenes.",
                       camera, [0, 0, 0], [0.2, 0.2, 0.2],
                       [{"position": [0.5, 2.1, 1.2], "color": [0.7, 0.7, 0.65]},
                        {"position": [1.3, 2.05, -2.3], "color": [0.35, 0.35, 0.38]}], materials, o)
