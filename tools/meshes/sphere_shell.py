#!/usr/bin/env python3
# Run from the repository root: python3 tools/meshes/sphere_shell.py
# Writes configs/meshes/sphere_shell.obj: a closed hollow sphere, outer radius 40 mm, inner 38 mm
# (a 2 mm wall), icosphere with 3 subdivisions; the inner surface's faces wind inward (its
# normals point into the cavity, out of the material). Exact sphere normals as vn.
import math
t=(1+5**0.5)/2
V=[(-1,t,0),(1,t,0),(-1,-t,0),(1,-t,0),(0,-1,t),(0,1,t),(0,-1,-t),(0,1,-t),(t,0,-1),(t,0,1),(-t,0,-1),(-t,0,1)]
V=[tuple(c/math.sqrt(sum(x*x for x in v)) for c in v) for v in V]
F=[(0,11,5),(0,5,1),(0,1,7),(0,7,10),(0,10,11),(1,5,9),(5,11,4),(11,10,2),(10,7,6),(7,1,8),(3,9,4),(3,4,2),(3,2,6),(3,6,8),(3,8,9),(4,9,5),(2,4,11),(6,2,10),(8,6,7),(9,8,1)]
for _ in range(3):
    cache={}; NF=[]
    def mid(a,b):
        k=(min(a,b),max(a,b))
        if k not in cache:
            p=[(V[a][i]+V[b][i])/2 for i in range(3)]; n=math.sqrt(sum(x*x for x in p))
            V.append(tuple(x/n for x in p)); cache[k]=len(V)-1
        return cache[k]
    for a,b,c in F:
        ab,bc,ca=mid(a,b),mid(b,c),mid(c,a)
        NF+= [(a,ab,ca),(b,bc,ab),(c,ca,bc),(ab,bc,ca)]
    F=NF
n=len(V)
with open('configs/meshes/sphere_shell.obj','w') as f:
    f.write('# lamprig: hollow sphere, outer radius 40 mm, inner 38 mm (2 mm wall), icosphere level 3.\n# Generated for configs/scenes/sphere_shell.json (issue 3 energy test); inner faces wind inward.\n')
    for R in (40.0,38.0):
        for v in V: f.write('v %.6f %.6f %.6f\n'%tuple(R*c for c in v))
    for s in (1,-1):
        for v in V: f.write('vn %.6f %.6f %.6f\n'%tuple(s*c for c in v))
    for a,b,c in F: f.write("f %d//%d %d//%d %d//%d\n"%(a+1,a+1,b+1,b+1,c+1,c+1))
    for a,b,c in F: f.write("f %d//%d %d//%d %d//%d\n"%(c+1+n,c+1+n,b+1+n,b+1+n,a+1+n,a+1+n))
