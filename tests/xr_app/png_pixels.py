"""Pixel checks of PNG files for the shell tests, with the standard library only (no imaging
package on the test machines): an 8-bit RGB or RGBA PNG decoded (all five row filters), the
pixels counted by class.

  png_pixels.py garment FRAME_NONE FRAME_EASE   the live garment's frames (drape_garment_xr_test)
  png_pixels.py dress FRAME_NONE FRAME_EASE     the same for a dress (from the shoulders down)
  png_pixels.py legend FIT_MAP                  the fit map's legend (drape_pattern_simulate_test)

Each check prints what it measured and exits 1 naming the check that failed."""
import struct
import sys
import zlib


def read_png(path):
    """(width, height, rows): rows[y][x] is an (r, g, b) tuple."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG")
    pos, idat, width, height, channels = 8, b"", 0, 0, 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
            channels = {2: 3, 6: 4}.get(colour, 0)
            if depth != 8 or not channels:
                sys.exit(f"{path}: not an 8-bit RGB or RGBA PNG")
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw, stride = zlib.decompress(idat), channels * width
    rows, above = [], bytearray(stride)
    for y in range(height):
        start = y * (stride + 1)
        filt, line = raw[start], bytearray(raw[start + 1:start + 1 + stride])
        for i in range(stride):
            left = line[i - channels] if i >= channels else 0
            up = above[i]
            corner = above[i - channels] if i >= channels else 0
            if filt == 1:
                line[i] = (line[i] + left) & 255
            elif filt == 2:
                line[i] = (line[i] + up) & 255
            elif filt == 3:
                line[i] = (line[i] + (left + up) // 2) & 255
            elif filt == 4:
                p = left + up - corner
                pa, pb, pc = abs(p - left), abs(p - up), abs(p - corner)
                pred = left if pa <= pb and pa <= pc else up if pb <= pc else corner
                line[i] = (line[i] + pred) & 255
        rows.append([tuple(line[x * channels:x * channels + 3]) for x in range(width)])
        above = line
    return width, height, rows


def saturated(p):
    """A colour of the maps' ramps (red, yellow, green, blue): far from grey."""
    return max(p) - min(p) > 90


def beige(p):
    """The dress form's cover: warm, light, little saturation."""
    r, g, b = p
    return r > 150 and r - b > 25 and max(p) - min(p) <= 90


def expect(ok, what):
    print(("ok: " if ok else "FAIL: ") + what)
    if not ok:
        sys.exit(1)


def check_garment(none_path, ease_path, dress=False):
    w, h, none = read_png(none_path)
    _, _, ease = read_png(ease_path)
    coloured = [(x, y) for y in range(h) for x in range(w) if saturated(ease[y][x])]
    before = sum(saturated(p) for row in none for p in row)
    expect(len(coloured) >= 1500, f"{len(coloured)} pixels in the ease map's colours (>= 1500)")
    # Before: only the form's reference lines and the hands' rays (red, blue, green) are.
    expect(before < len(coloured) / 10,
           f"{before} such pixels before the map was toggled on (< a tenth of them)")
    # The garment's box: the rows and columns holding at least 8 such pixels (a hand's ray, thin,
    # crosses a row or column in one or two).
    per_x, per_y = [0] * w, [0] * h
    for x, y in coloured:
        per_x[x] += 1
        per_y[y] += 1
    xs, ys = [x for x in range(w) if per_x[x] >= 8], [y for y in range(h) if per_y[y] >= 8]
    x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
    expect(y1 - y0 > 0.2 * h, f"the garment's rows {y0}..{y1} ({y1 - y0} px tall, > {0.2 * h:.0f})")
    cx = (x0 + x1) / 2
    expect(abs(cx - w / 2) < 0.1 * w, f"the garment's columns {x0}..{x1} centred (the form's)")
    expect(x1 - x0 < 0.4 * w, f"the garment {x1 - x0} px wide (< {0.4 * w:.0f}: on the form)")
    if dress:
        # A dress covers the form from the shoulders to below the hip: taller than a skirt, its
        # top in the upper third of the frame, and under the neck little of the form is seen.
        expect(y1 - y0 > 0.35 * h, f"the dress {y1 - y0} px tall (> {0.35 * h:.0f})")
        expect(y0 < h / 3, f"the dress's top row {y0} in the upper third (< {h / 3:.0f})")
    else:
        form_above = sum(beige(none[y][x]) for y in range(0, y0) for x in range(x0, x1 + 1))
        expect(form_above >= 300,
               f"{form_above} pixels of the form above the garment's top row {y0}")
    changed = sum(none[y][x] != ease[y][x] for x, y in coloured)
    expect(changed >= 0.9 * len(coloured), f"{changed} of them differ from the frame without it")


def check_legend(path):
    w, h, rows = read_png(path)
    # The legend: the rows below the four views (tiles of 640 rows each).
    legend = rows[1280:]
    expect(len(legend) >= 60, f"{len(legend)} legend rows below the views (>= 60)")
    for name, half in (("ease", range(0, w // 2)), ("strain", range(w // 2, w))):
        bar = [legend[y][x] for y in range(len(legend)) for x in half]
        ramp = sum(saturated(p) for p in bar)
        dark = sum(max(p) < 80 for p in bar)
        expect(ramp >= 2000, f"{name}: {ramp} pixels of its colour bar (>= 2000)")
        expect(dark >= 200, f"{name}: {dark} dark pixels of its labels (>= 200)")
        # The bar's ends along its fullest row: ease red (tight) to blue (loose), strain blue
        # (compressed) to red (stretched).
        row = max(legend, key=lambda r: sum(saturated(r[x]) for x in half))
        ends = [row[x] for x in half if saturated(row[x])]
        red = lambda p: p[0] > p[2] + 80
        blue = lambda p: p[2] > p[0] + 50
        first, last = (red, blue) if name == "ease" else (blue, red)
        expect(first(ends[0]) and last(ends[-1]), f"{name}: its bar runs {ends[0]} .. {ends[-1]}")


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] in ("garment", "dress"):
        check_garment(sys.argv[2], sys.argv[3], dress=sys.argv[1] == "dress")
    elif len(sys.argv) == 3 and sys.argv[1] == "legend":
        check_legend(sys.argv[2])
    else:
        sys.exit(__doc__)
