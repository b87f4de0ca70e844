#!/usr/bin/env python3
"""Writes configs/meshes/votive.obj: a wax votive (a cup that holds a tealight), the example of
a designer's own mockup mesh. Quads, 1-based and negative (relative) indices, vertex normals
omitted so that the loader computes them. Millimetres, z up, standing on z = 0.

    python3 tools/meshes/votive.py > configs/meshes/votive.obj
"""
import math

N = 32                       # segments around
R_OUT, R_IN = 40.0, 33.0     # outer and cavity radius
H, FLOOR = 65.0, 8.0         # height and floor thickness

rings = [(0.0, 0.0), (R_OUT, 0.0), (R_OUT, H), (R_IN, H), (R_IN, FLOOR), (0.0, FLOOR)]
print("# votive: a wax cup for a tealight, mm, z up (tools/meshes/votive.py)")
print("o votive")
verts = []
for (r, z) in rings:
    if r == 0.0:
        verts.append([(0.0, 0.0, z)])
    else:
        verts.append([(r * math.cos(2 * math.pi * j / N), r * math.sin(2 * math.pi * j / N), z)
                      for j in range(N)])
index = []
count = 0
for ring in verts:
    first = count + 1
    for (x, y, z) in ring:
        print("v %.6f %.6f %.6f" % (x, y, z))
        count += 1
    index.append(first)
print("s 1")
# Outward winding: the profile runs bottom centre -> rim -> inside -> cavity floor centre.
for k in range(len(rings) - 1):
    a, b = index[k], index[k + 1]
    pa, pb = len(verts[k]) == 1, len(verts[k + 1]) == 1
    for j in range(N):
        j1 = (j + 1) % N
        A = a if pa else a + j
        B = a if pa else a + j1
        C = b if pb else b + j1
        D = b if pb else b + j
        if pa:
            corners = [A, C, D]
        elif pb:
            corners = [A, B, C]
        else:
            corners = [A, B, C, D]
        # Every other face with negative indices (relative to the vertex count so far).
        if j % 2:
            print("f " + " ".join(str(c - count - 1) for c in corners))
        else:
            print("f " + " ".join(str(c) for c in corners))
