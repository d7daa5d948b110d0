"""Image files the library reads, written with the standard library only: uncompressed OpenEXR
(float or half channels) and 8-bit PNG. The scene-file writer (scene_file.py) stores a scene's
textures and environment world in them, so that the file bakes to the same bits as the scene it
was written from: an EXR's float channels and a PNG's bytes read back exactly. Tests use them to
make image files too.

Texels come bottom row first (v = 0, Blender's Image.pixels order); both formats store the top
row first, so rows are written in reverse.
"""
from __future__ import annotations

import array
import struct
import sys
import zlib
from typing import Sequence

EXR_CHANNELS = {1: ("Y",), 3: ("R", "G", "B"), 4: ("R", "G", "B", "A")}


def _attribute(name: str, kind: str, value: bytes) -> bytes:
    return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value


def exr_bytes(texels: Sequence[float], width: int, height: int, channels: int, half: bool = False,
              names: Sequence[str] = ()) -> bytes:
    """A single-part scanline OpenEXR (OpenEXR file layout: magic, version 2, header attributes,
    offset table, one uncompressed scanline a chunk) holding `channels` interleaved channels of
    `texels`, as FLOAT (or HALF) channels named R G B A / Y (or `names`, in texel order)."""
    names = tuple(names) or EXR_CHANNELS[channels]
    if len(names) != channels or len(texels) != width * height * channels:
        raise ValueError(f"{len(texels)} texels for {width} x {height} x {channels} ({len(names)} names)")
    values = array.array("f", texels)
    order = sorted(range(channels), key=lambda c: names[c])  # EXR lists channels sorted by name
    pixel_type = 1 if half else 2
    chlist = b"".join(names[c].encode() + b"\0" + struct.pack("<iB3xii", pixel_type, 0, 1, 1) for c in order) + b"\0"
    box = struct.pack("<iiii", 0, 0, width - 1, height - 1)
    header = (b"\x76\x2f\x31\x01" + struct.pack("<i", 2) + _attribute("channels", "chlist", chlist) +
              _attribute("compression", "compression", b"\0") + _attribute("dataWindow", "box2i", box) +
              _attribute("displayWindow", "box2i", box) + _attribute("lineOrder", "lineOrder", b"\0") +
              _attribute("pixelAspectRatio", "float", struct.pack("<f", 1.0)) +
              _attribute("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0)) +
              _attribute("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0")
    row_values = width * channels
    chunks = []
    for y in range(height):  # file row y (top first) is texel row height - 1 - y
        row = values[(height - 1 - y) * row_values:(height - y) * row_values]
        parts = []
        for c in order:
            column = row[c::channels]
            if half:
                parts.append(struct.pack(f"<{width}e", *column))
            else:
                if sys.byteorder != "little":
                    column.byteswap()
                parts.append(column.tobytes())
        data = b"".join(parts)
        chunks.append(struct.pack("<ii", y, len(data)) + data)
    offsets, position = [], len(header) + 8 * height
    for chunk in chunks:
        offsets.append(position)
        position += len(chunk)
    return header + struct.pack(f"<{height}Q", *offsets) + b"".join(chunks)


def png_bytes(texels: bytes, width: int, height: int, channels: int) -> bytes:
    """An 8-bit PNG (grey, RGB or RGBA for 1, 3, 4 channels; PNG specification: signature,
    IHDR, one zlib IDAT of filter-0 rows, IEND) of the bytes `texels`."""
    if len(texels) != width * height * channels or channels not in (1, 3, 4):
        raise ValueError(f"{len(texels)} bytes for {width} x {height} x {channels}")

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    colour_type = {1: 0, 3: 2, 4: 6}[channels]
    stride = width * channels
    rows = b"".join(b"\0" + texels[(height - 1 - y) * stride:(height - y) * stride] for y in range(height))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(rows, 6)) + chunk(b"IEND", b""))
