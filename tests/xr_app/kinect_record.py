#!/usr/bin/env python3
"""A fakenect recording (libfreenect's replay format, docs/tracking.md) of the palm path of
hands_trace.py seen by a Kinect v1 depth camera, for drape_hands_test.sh's kinect modes.

The camera stands behind the form at CAMERA (stage metres) and looks at the user, along the
stage's +z (its own -z, y up): camera = R^T (stage - CAMERA) with R a half turn about y. The
calibration file written next to the recording maps the camera frame back into the stage
(stage = R camera + CAMERA). Each depth frame is a wall, the user's torso and the palm as a disc
of 8 cm radius at its depth, as 11-bit raw disparity (Burrus' fit, the inverse of
tracking/kinect.cpp's kinect_raw_to_m), 30 frames per second.

usage: kinect_record.py DIR CALIBRATION.json PX PY PZ [--until SECONDS]
  --until: the recording stops at this time of the path (the Kinect going away mid-gesture).
"""
import array
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hands_trace  # noqa: E402

W, H = 640, 480
FX, FY, CX, CY = 594.214, 591.040, 339.308, 242.739  # tracking::DepthIntrinsics
CAMERA = (0.0, 1.2, -1.0)
RATE = 30.0
PALM_RADIUS = 0.08
WALL, TORSO = 2.6, 1.9  # depths (m)


def raw(metres):
    """Metres -> 11-bit raw disparity (tracking::kinect_m_to_raw)."""
    r = (1.0 / metres - 3.3309495161) / -0.0030711016
    return max(0, min(2047, int(round(r))))


def to_camera(p):
    """Stage point -> camera point (a half turn about y after the camera's offset)."""
    d = [p[i] - CAMERA[i] for i in range(3)]
    return (-d[0], d[1], -d[2])


def frame(palm):
    """One depth frame (raw values, row-major) with the palm at the camera point `palm`."""
    x, y, z = palm
    depth = -z
    u0, v0 = FX * x / depth + CX, -FY * y / depth + CY
    r_px = PALM_RADIUS * FX / depth
    wall_row = array.array("H", [raw(WALL)]) * W
    torso_row = array.array("H", wall_row)
    torso_row[220:420] = array.array("H", [raw(TORSO)]) * 200
    out = array.array("H")
    hand = raw(depth)
    for v in range(H):
        row = array.array("H", torso_row if v > 150 else wall_row)
        dv = v - v0
        if abs(dv) < r_px:
            half = math.sqrt(r_px * r_px - dv * dv)
            a = max(0, int(math.ceil(u0 - half)))
            b = min(W, int(math.floor(u0 + half)) + 1)
            if b > a:
                row[a:b] = array.array("H", [hand]) * (b - a)
        out.extend(row)
    if sys.byteorder != "little":
        out.byteswap()
    return out.tobytes()


def main():
    a = sys.argv[1:]
    if len(a) < 5:
        sys.exit(__doc__)
    out_dir, calibration = a[0], a[1]
    p = tuple(map(float, a[2:5]))
    until = float(a[a.index("--until") + 1]) if "--until" in a else 1e9
    os.makedirs(out_dir, exist_ok=True)
    path = hands_trace.path(p)
    step = int(round(hands_trace.RATE / RATE))
    names = []
    for i in range(0, len(path), step):
        t, pos = path[i]
        if t > until:
            break
        name = "d-%.6f-%u.pgm" % (1000.0 + t, 1000 + int(t * 1e5))
        with open(os.path.join(out_dir, name), "wb") as f:
            f.write(b"P5 640 480 65535\n")
            f.write(frame(to_camera(pos)))
        names.append(name)
    with open(os.path.join(out_dir, "INDEX.txt"), "w") as f:
        f.write("".join(n + "\n" for n in names))
    with open(calibration, "w") as f:
        f.write('{"format": "drape-calibration", "version": 1, "scale": 1.0,\n'
                ' "rotation": [[-1,0,0],[0,1,0],[0,0,-1]], "translation": [%g, %g, %g],\n'
                ' "rms_residual_m": 0.0, "max_residual_m": 0.0, "pairs": 4}\n' % CAMERA)


if __name__ == "__main__":
    main()
