#!/usr/bin/env python3
"""Writes the tiny TressFX project in mini/ (test data for tfx_test and fuzz seeds).

The .tfx files are written with Python's struct module straight from the layouts in
scenarios/assets/tressfx/README.md, independently of the C++ reader they test.
Run from this folder: python3 make_mini.py
"""
import math
import struct


def strand(root_angle, n, length, bend):
    """A strand rooted on a 10 cm sphere, leaving it radially and curling downward."""
    c, s = math.cos(root_angle), math.sin(root_angle)
    root = (10.0 * c, 10.0, 10.0 * s)
    pts = []
    for i in range(n):
        u = i / (n - 1)
        out = length * u
        pts.append((root[0] + out * c, root[1] - bend * out * out, root[2] + out * s))
    return pts


def write_v3(path, strands, both_ends):
    n = len(strands[0])
    header = struct.pack('<f4I', 3.0, len(strands), n, 0, both_ends)
    header += b'\0' * (31 * 4)
    header += struct.pack('<6I', 296, 0, 0, 0, 0, 0)
    header += b'\0' * (32 * 4)
    assert len(header) == 296
    body = b''.join(struct.pack('<3f', *p) for st in strands for p in st)
    open(path, 'wb').write(header + body)


def write_v4(path, strands, inverse_masses, uvs):
    n = len(strands[0])
    positions_at = 160
    uv_at = positions_at + 16 * n * len(strands)
    header = struct.pack('<f7I', 4.0, len(strands), n, positions_at, uv_at, 0, 0, 0)
    header += b'\0' * (32 * 4)
    assert len(header) == 160
    body = b''.join(struct.pack('<4f', *p, w) for st in strands for p, w in zip(st, inverse_masses))
    uv = b''.join(struct.pack('<2f', *t) for t in uvs)
    open(path, 'wb').write(header + body + uv)


write_v3('mini/a.tfx', [strand(a, 4, 6.0, 0.05) for a in (0.0, 0.5, 1.0)], both_ends=0)
# Only vertex 0 pinned in the file, as some exporters write it: the reader pins vertex 1.
write_v4('mini/b.tfx', [strand(a, 5, 8.0, 0.08) for a in (2.0, 2.5)],
         inverse_masses=(0.0, 1.0, 1.0, 1.0, 1.0), uvs=((0.25, 0.5), (0.75, 0.125)))
