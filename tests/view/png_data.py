"""The image data of a PNG, for the view tests: the same pixels through algray's one encoder give the same bytes,
whatever text chunks (the scene, the software) the files carry."""
import struct
import zlib


def idat(png):
    assert png[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, data = 8, b""
    while pos < len(png):
        length, kind = struct.unpack(">I4s", png[pos:pos + 8])
        if kind == b"IDAT":
            data += png[pos + 8:pos + 8 + length]
        pos += 12 + length
    return zlib.decompress(data)
