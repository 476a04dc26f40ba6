#!/usr/bin/env python3
"""Write ellipse.obj: the drop of dropletOscillation, an elliptic cylinder
whose section at z = 0 is the 2-D drop. Semi-axes a = e R, b = R / e (the
area of the circle of radius R, pi R^2), e = 1.08: a mode-2 deformation of
8% with no corners (a rectangle's corners drive jets that shed particles).
Run: python3 makeEllipse.py > ellipse.obj"""
import math

R, E, N, Z = 0.0222, 1.08, 180, 0.005
a, b = R * E, R / E
print("# dropletOscillation: elliptic cylinder, a = %.6g m, b = %.6g m, z in [-%g, %g] m "
      "(makeEllipse.py)" % (a, b, Z, Z))
for z in (-Z, Z):
    for k in range(N):
        t = 2 * math.pi * k / N
        print("v %.9g %.9g %.9g" % (a * math.cos(t), b * math.sin(t), z))
print("v 0 0 %g" % -Z)
print("v 0 0 %g" % Z)
bottom, top = 2 * N + 1, 2 * N + 2
for k in range(N):  # faces counter-clockwise seen from outside: outward normals
    k1 = (k + 1) % N
    print("f %d %d %d" % (k + 1, k1 + 1, N + k1 + 1))
    print("f %d %d %d" % (k + 1, N + k1 + 1, N + k + 1))
    print("f %d %d %d" % (bottom, k1 + 1, k + 1))
    print("f %d %d %d" % (top, N + k + 1, N + k1 + 1))
