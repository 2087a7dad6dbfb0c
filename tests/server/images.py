"""What the server tests check images with: small PNG / OpenEXR decoders (no image library in the
venv), the renderer's 8-bit tone mapping, a canvas painted from the event stream, and the same
render from the pathtracer CLI for comparison."""
import base64
import struct
import subprocess
import zlib
from pathlib import Path

from support import PATHTRACER


def decode_png(data):
    """8-bit PNG -> (width, height, RGB bytes). Handles every filter; no interlacing."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, ihdr = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        elif kind == b"IEND":
            break
    width, height, depth, color, _, _, interlace = ihdr
    assert depth == 8 and interlace == 0, ihdr
    channels = {0: 1, 2: 3, 4: 2, 6: 4}[color]
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line))
        prev = line
    pixels = b"".join(rows)
    if channels != 3:  # to RGB
        out = bytearray()
        for i in range(0, len(pixels), channels):
            px = pixels[i:i + channels]
            out += bytes(px[:1] * 3) if channels <= 2 else bytes(px[:3])
        pixels = bytes(out)
    return width, height, pixels


def read_exr(data):
    """Scanline OpenEXR (NONE / ZIPS / ZIP, HALF or FLOAT channels) -> (width, height,
    {channel: [floats]}, {attribute: value}); string attributes decoded, others raw bytes."""
    assert data[:4] == b"\x76\x2f\x31\x01", "not an OpenEXR file"
    assert not struct.unpack("<I", data[4:8])[0] & 0x200, "tiled EXR not supported"
    pos, attrs = 8, {}
    while data[pos] != 0:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        tend = data.index(b"\0", end + 1)
        kind = data[end + 1:tend].decode()
        size = struct.unpack("<i", data[tend + 1:tend + 5])[0]
        value = data[tend + 5:tend + 5 + size]
        attrs[name] = value.decode(errors="replace") if kind == "string" else (kind, value)
        pos = tend + 5 + size
    pos += 1
    channels, chl = [], attrs["channels"][1]
    p = 0
    while chl[p] != 0:
        end = chl.index(b"\0", p)
        ptype = struct.unpack("<i", chl[end + 1:end + 5])[0]
        channels.append((chl[p:end].decode(), ptype))
        p = end + 17
    compression = attrs["compression"][1][0]
    xmin, ymin, xmax, ymax = struct.unpack("<4i", attrs["dataWindow"][1])
    width, height = xmax - xmin + 1, ymax - ymin + 1
    lines = {0: 1, 2: 1, 3: 16}[compression]
    nblocks = (height + lines - 1) // lines
    offsets = struct.unpack(f"<{nblocks}Q", data[pos:pos + 8 * nblocks])
    out = {name: [0.0] * (width * height) for name, _ in channels}
    for off in offsets:
        y, size = struct.unpack("<ii", data[off:off + 8])
        block = data[off + 8:off + 8 + size]
        nlines = min(lines, ymax + 1 - y)
        expected = sum(width * (2 if t == 1 else 4) for _, t in channels) * nlines
        if compression != 0 and size < expected:
            t = bytearray(zlib.decompress(block))
            for i in range(1, len(t)):  # undo the predictor, then the byte interleave
                t[i] = (t[i - 1] + t[i] - 128) & 255
            half = (len(t) + 1) // 2
            block = bytearray(len(t))
            block[0::2] = t[:half]
            block[1::2] = t[half:]
        q = 0
        for row in range(nlines):
            for name, ptype in channels:
                fmt, step = ("<e", 2) if ptype == 1 else ("<f", 4)
                vals = struct.unpack(f"<{width}{fmt[1]}", bytes(block[q:q + width * step]))
                q += width * step
                base = (y - ymin + row) * width
                out[name][base:base + width] = vals
    return width, height, out, attrs


def tonemap_course(v):
    """The renderer's 8-bit tone mapping (renderer/util/image.cpp), for cross-checking decoders."""
    if not v > 0:
        return 0
    t = (1.41421356 * v) ** (1 / 2.2)
    return int(min(max(t, 0.0), 1.0) * 255.0)


def stream_tile_size(tile_size):
    return tile_size * -(-64 // tile_size)


class Canvas:
    """An RGB image painted from the event stream's image and tile events."""

    def __init__(self, width, height, tile_size):
        # The stream sends squares of whole render tiles, at least 64 pixels a side (the status's
        # stream_tile_size), whatever tile size the job renders with.
        self.width, self.height, self.tile_size = width, height, stream_tile_size(tile_size)
        self.pixels = bytearray(width * height * 3)
        self.painted = set()

    def paint_image(self, data):
        w, h, px = decode_png(base64.b64decode(data["png"]))
        assert (w, h) == (data["width"], data["height"]) == (self.width, self.height)
        self.pixels[:] = px
        self.painted = {(x, y) for x in range(0, w, self.tile_size) for y in range(0, h, self.tile_size)}

    def paint_tile(self, data):
        x, y, w, h, ts = data["x"], data["y"], data["w"], data["h"], self.tile_size
        # Tiles lie on the tile grid and are clipped at the right and bottom edges.
        assert x % ts == 0 and y % ts == 0, data
        assert (w, h) == (min(ts, self.width - x), min(ts, self.height - y)), data
        tw, th, px = decode_png(base64.b64decode(data["png"]))
        assert (tw, th) == (w, h), f"tile PNG is {tw}x{th}, event says {w}x{h}"
        for row in range(h):
            start = ((y + row) * self.width + x) * 3
            self.pixels[start:start + w * 3] = px[row * w * 3:(row + 1) * w * 3]
        self.painted.add((x, y))

    def tile_count(self):
        ts = self.tile_size
        return ((self.width + ts - 1) // ts) * ((self.height + ts - 1) // ts)


# ---- the CLI renderer, with a job's normalised spec ----
def cli_args(spec, threads=2):
    """pathtracer flags for a job spec, every parameter explicit (the CLI's defaults differ)."""
    args = ["-t", str(threads), "-s", str(spec["spp"]), "-m", str(spec["max_depth"]),
            "-l", str(spec["light_samples"]), "-r", str(spec["width"]), str(spec["height"]),
            "-b", repr(spec["aperture"]), "-d", repr(spec["focal_distance"]),
            "--seed", str(spec["seed"]), "--tile", str(spec["tile_size"]), "--quiet"]
    if spec["adaptive"]:
        args += ["-a", str(spec["adaptive_batch"]), repr(spec["adaptive_tolerance"])]
    else:
        args += ["--no-adaptive"]
    if spec["hemisphere"]:
        args.append("-H")
    if spec["file_camera"]:
        args.append("--file-camera")
    if spec.get("keep_fov"):
        args.append("--keep-fov")
    if not spec.get("caustic_tracing", True):
        args.append("--no-caustic-tracing")
    cam = spec.get("camera")
    if cam:  # the CLI's --camera has world up
        assert cam.get("up") in (None, [0, 1, 0]), "the CLI's --camera has no up vector"
        args += ["--camera", *map(repr, cam["position"]), *map(repr, cam["target"]), repr(cam.get("vfov") or 0)]
    return args


def render_cli(spec, scene_file, out_file, threads=2):
    cmd = [str(PATHTRACER), *cli_args(spec, threads), "-f", str(out_file), str(scene_file)]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, f"{' '.join(cmd)}\n{done.stdout}{done.stderr}"
    return Path(out_file).read_bytes()

