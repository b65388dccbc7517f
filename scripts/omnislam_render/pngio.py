"""Minimal PNG reader (8 or 16 bit; gray, gray+alpha, RGB, RGBA; non-interlaced).

The renderer itself never decodes images; this exists so the tests and the
convention check can compare images without adding an imaging dependency.
"""
from __future__ import annotations

import struct
import zlib

import numpy as np

_CHANNELS = {0: 1, 2: 3, 4: 2, 6: 4}


def _paeth_row(line: np.ndarray, prev: np.ndarray, bpp: int) -> np.ndarray:
    out = np.empty_like(line, dtype=np.int32)
    cur = line.astype(np.int32)
    up = prev.astype(np.int32)
    for i in range(0, len(cur), bpp):
        a = out[i - bpp:i] if i >= bpp else np.zeros(bpp, np.int32)
        b = up[i:i + bpp]
        c = up[i - bpp:i] if i >= bpp else np.zeros(bpp, np.int32)
        p = a + b - c
        pa, pb, pc = np.abs(p - a), np.abs(p - b), np.abs(p - c)
        pred = np.where((pa <= pb) & (pa <= pc), a, np.where(pb <= pc, b, c))
        out[i:i + bpp] = (cur[i:i + bpp] + pred) & 0xFF
    return out.astype(np.uint8)


def _sub_row(line: np.ndarray, bpp: int, base: np.ndarray | None = None) -> np.ndarray:
    # Sub (and Average without the 'up' term) is a running sum per channel.
    vals = line.astype(np.int64).reshape(-1, bpp)
    return (np.cumsum(vals, axis=0) & 0xFF).astype(np.uint8).reshape(-1)


def _avg_row(line: np.ndarray, prev: np.ndarray, bpp: int) -> np.ndarray:
    out = np.empty(len(line), np.int32)
    cur = line.astype(np.int32)
    up = prev.astype(np.int32)
    for i in range(0, len(cur), bpp):
        left = out[i - bpp:i] if i >= bpp else 0
        out[i:i + bpp] = (cur[i:i + bpp] + ((left + up[i:i + bpp]) >> 1)) & 0xFF
    return out.astype(np.uint8)


def read_png(path) -> np.ndarray:
    """Return the image as uint8/uint16 array (H, W) or (H, W, C)."""
    with open(path, "rb") as fh:
        data = fh.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG file")
    pos, idat = 8, []
    width = height = depth = ctype = interlace = None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            width, height, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
    if depth not in (8, 16) or ctype not in _CHANNELS or interlace:
        raise ValueError(f"{path}: unsupported PNG (depth {depth}, type {ctype}, interlace {interlace})")
    channels = _CHANNELS[ctype]
    bpp = channels * depth // 8
    stride = width * bpp
    raw = np.frombuffer(zlib.decompress(b"".join(idat)), np.uint8).reshape(height, stride + 1)
    img = np.zeros((height, stride), np.uint8)
    prev = np.zeros(stride, np.uint8)
    for y in range(height):
        ftype, line = raw[y, 0], raw[y, 1:]
        if ftype == 0:
            row = line.copy()
        elif ftype == 1:
            row = _sub_row(line, bpp)
        elif ftype == 2:
            row = ((line.astype(np.int32) + prev) & 0xFF).astype(np.uint8)
        elif ftype == 3:
            row = _avg_row(line, prev, bpp)
        elif ftype == 4:
            row = _paeth_row(line, prev, bpp)
        else:
            raise ValueError(f"{path}: bad filter type {ftype}")
        img[y] = row
        prev = row
    if depth == 16:
        img = img.view(">u2").astype(np.uint16)
    return img.reshape(height, width, channels) if channels > 1 else img.reshape(height, width)


def read_ppm(path) -> np.ndarray:
    """Binary PPM (P6), 8 or 16 bit, as an (H, W, 3) uint8/uint16 array."""
    data = open(path, "rb").read()
    fields, pos = [], 0
    while len(fields) < 4:
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    if fields[0] != b"P6":
        raise ValueError(f"{path}: not a binary PPM")
    width, height, maxval = (int(f) for f in fields[1:])
    pos += 1  # the single whitespace after maxval
    dtype = np.dtype(">u2") if maxval > 255 else np.dtype(np.uint8)
    pixels = np.frombuffer(data, dtype, count=width * height * 3, offset=pos)
    return pixels.reshape(height, width, 3).astype(np.uint16 if maxval > 255 else np.uint8)


def strip_timestamps(path) -> None:
    """Drop the chunks that make POV-Ray's PNGs differ between identical renders
    (tIME and the tEXt comment holding the render date); pixels are untouched."""
    data = open(path, "rb").read()
    out, pos = [data[:8]], 8
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        chunk = data[pos:pos + 12 + length]
        pos += 12 + length
        if kind == b"tIME" or (kind == b"tEXt" and not chunk[8:].startswith(b"Software\x00")):
            continue
        out.append(chunk)
    with open(path, "wb") as fh:
        fh.write(b"".join(out))


def write_png_gray(path, image: np.ndarray) -> None:
    """Write an 8-bit grey image as a PNG (filter 'Up' on every row, zlib level 9)."""
    image = np.ascontiguousarray(image, dtype=np.uint8)
    height, width = image.shape
    up = np.diff(image.astype(np.int16), axis=0, prepend=0).astype(np.uint8)
    raw = np.hstack([np.full((height, 1), 2, np.uint8), up]).tobytes()

    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    header = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    with open(path, "wb") as fh:
        fh.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 9))
                 + chunk(b"IEND", b""))


def to_gray(image: np.ndarray) -> np.ndarray:
    """8-bit luma, 0.299 R + 0.587 G + 0.114 B rounded (ITU-R BT.601, the weights OpenCV's
    grey conversion uses); the front-end reads every image as grey anyway."""
    if image.ndim == 2:
        return image.astype(np.uint8)
    rgb = image[..., :3].astype(np.int32)
    # cvtColor's fixed-point form: 14-bit coefficients, rounded.
    luma = (rgb[..., 0] * 4899 + rgb[..., 1] * 9617 + rgb[..., 2] * 1868 + (1 << 13)) >> 14
    return luma.astype(np.uint8)
