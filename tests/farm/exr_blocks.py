"""The pixel blocks of an OpenEXR file, for comparing two files' pixels bit for bit whatever their
headers say (tests/farm). Standard library only."""
import struct


def read(path: str) -> bytes:
    with open(path, "rb") as f:
        return f.read()


def exr_pixel_blocks(path: str) -> list:
    """The pixel blocks of a scanline OpenEXR file as (y, bytes) pairs in file order: every layer's
    values (RGBA, variance, sample counts) as the library compressed them, without the header
    (whose dwivedi:seconds and dwivedi:error_vs_time differ between a bake and a merge). Equal
    blocks under the same compression are equal pixels. OpenEXR file layout: magic and version
    (8 bytes), attributes (name, type, int32 size, value) up to an empty name, the offset table
    (one uint64 a block), then the blocks (int32 y, int32 size, data)."""
    data = read(path)
    assert data[:4] == b"\x76\x2f\x31\x01", f"{path} is not an OpenEXR file"
    at = 8
    while data[at] != 0:
        at = data.index(b"\0", at) + 1          # name
        at = data.index(b"\0", at) + 1          # type
        (size,) = struct.unpack_from("<i", data, at)
        at += 4 + size
    at += 1
    (first,) = struct.unpack_from("<Q", data, at)
    offsets = struct.unpack_from(f"<{(first - at) // 8}Q", data, at)
    blocks = []
    for offset in offsets:
        y, size = struct.unpack_from("<ii", data, offset)
        blocks.append((y, data[offset + 8:offset + 8 + size]))
    return blocks
