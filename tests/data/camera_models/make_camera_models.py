#!/usr/bin/env python3
"""Writes the small COLMAP text model and nerfstudio transforms.json of this folder, in the layouts their
projects document (COLMAP: "Output Format", cameras.txt / images.txt / points3D.txt; nerfstudio: "Data
conventions", transforms.json), not with tilesplat's writer. The poses are views 2 and 5 of the bundled
playbot's cameras.json (camera-to-world rotations, OpenCV axes), so that a test can check the readers
against that file. Run from the repository root; the outputs are committed.

    python3 tests/data/camera_models/make_camera_models.py
"""
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
views = json.load(open(os.path.join(HERE, "../../../scenes/playbot_lod3/playbot_lod3_31000_sh2.json")))
picked = [views[2], views[5]]


def transpose(m):
    return [[m[c][r] for c in range(3)] for r in range(3)]


def quaternion(r):  # rotation matrix -> (w, x, y, z), w >= 0 (Shepperd's method)
    trace = r[0][0] + r[1][1] + r[2][2]
    if trace > 0:
        s = 2 * math.sqrt(1 + trace)
        q = (s / 4, (r[2][1] - r[1][2]) / s, (r[0][2] - r[2][0]) / s, (r[1][0] - r[0][1]) / s)
    elif r[0][0] > r[1][1] and r[0][0] > r[2][2]:
        s = 2 * math.sqrt(1 + r[0][0] - r[1][1] - r[2][2])
        q = ((r[2][1] - r[1][2]) / s, s / 4, (r[0][1] + r[1][0]) / s, (r[0][2] + r[2][0]) / s)
    elif r[1][1] > r[2][2]:
        s = 2 * math.sqrt(1 + r[1][1] - r[0][0] - r[2][2])
        q = ((r[0][2] - r[2][0]) / s, (r[0][1] + r[1][0]) / s, s / 4, (r[1][2] + r[2][1]) / s)
    else:
        s = 2 * math.sqrt(1 + r[2][2] - r[0][0] - r[1][1])
        q = ((r[1][0] - r[0][1]) / s, (r[0][2] + r[2][0]) / s, (r[1][2] + r[2][1]) / s, s / 4)
    return q if q[0] >= 0 else tuple(-v for v in q)


def num(v):
    return repr(float(v))


# COLMAP: camera 1 SIMPLE_PINHOLE (f, cx, cy), camera 2 PINHOLE (fx, fy, cx, cy); world-to-camera poses.
sparse = os.path.join(HERE, "colmap", "sparse", "0")
os.makedirs(sparse, exist_ok=True)
with open(os.path.join(sparse, "cameras.txt"), "w") as f:
    f.write("# Camera list with one line of data per camera:\n")
    f.write("#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n")
    f.write("# Number of cameras: 2\n")
    a, b = picked
    f.write(f"1 SIMPLE_PINHOLE {a['width']} {a['height']} {num(a['fx'])} 960 540\n")
    f.write(f"2 PINHOLE {b['width']} {b['height']} {num(b['fx'])} {num(b['fy'])} 960 540\n")
with open(os.path.join(sparse, "images.txt"), "w") as f:
    f.write("# Image list with two lines of data per image:\n")
    f.write("#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n")
    f.write("#   POINTS2D[] as (X, Y, POINT3D_ID)\n")
    f.write("# Number of images: 2, mean observations per image: 1.5\n")
    for image_id, (camera_id, view) in enumerate([(1, picked[0]), (2, picked[1])], start=1):
        w2c = transpose(view["rotation"])
        c = view["position"]
        t = [-sum(w2c[r][k] * c[k] for k in range(3)) for r in range(3)]
        q = quaternion(w2c)
        f.write(" ".join([str(image_id)] + [num(v) for v in q] + [num(v) for v in t] +
                         [str(camera_id), f"frame_{image_id:05d}.jpg"]) + "\n")
        f.write("812.5 402.25 1 1003.0 588.75 -1\n" if image_id == 1 else "955.0 521.5 1\n")
with open(os.path.join(sparse, "points3D.txt"), "w") as f:
    f.write("# 3D point list with one line of data per point:\n")
    f.write("#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n")
    f.write("# Number of points: 1, mean track length: 2\n")
    f.write("1 0.05 -0.4 0.02 201 120 40 0.71 1 0 2 0\n")

# nerfstudio: OpenGL camera axes (x right, y up, z back), camera-to-world. Frame 0 is view 2 as it is;
# frame 1 the same pose with its principal point moved by (+64, +128) pixels at 1920x1080.
def gl_matrix(view):
    r = view["rotation"]
    m = [[r[row][0], -r[row][1], -r[row][2], view["position"][row]] for row in range(3)]
    return m + [[0.0, 0.0, 0.0, 1.0]]


a = picked[0]
doc = {
    "camera_model": "OPENCV",
    "fl_x": a["fx"], "fl_y": a["fy"], "cx": 960.0, "cy": 540.0, "w": a["width"], "h": a["height"],
    "k1": 0.0, "k2": 0.0, "p1": 0.0, "p2": 0.0,
    "frames": [
        {"file_path": "images/frame_00001.png", "transform_matrix": gl_matrix(a)},
        {"file_path": "images/frame_00002.png", "cx": 1024.0, "cy": 668.0, "transform_matrix": gl_matrix(a)},
    ],
}
os.makedirs(os.path.join(HERE, "nerfstudio"), exist_ok=True)
with open(os.path.join(HERE, "nerfstudio", "transforms.json"), "w") as f:
    json.dump(doc, f, indent=2)
    f.write("\n")
