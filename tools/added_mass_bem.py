#!/usr/bin/env python3
"""The added-mass coefficient of a circle started impulsively in a rectangular tank of water
with a free surface, by potential flow: the reference of the added-mass tests of
tests/bodies.rs, whose tank is close enough for its walls and surface to move Ca off the
unbounded 1 (docs/bodies.md, "Measured").

    tools/added_mass_bem.py WIDTH DEPTH CX CY RADIUS
        prints Ca for a motion along x and along y, at two resolutions (their difference
        bounds the discretisation's error)

An impulsive start (and the release of a body at rest) sees the free surface as φ = 0 (no
pressure impulse there), the walls and the floor as ∂φ/∂n = 0, and the circle as ∂φ/∂n = U·n.
Ca = −∫ φ U·n ds / (π r²) over the circle for |U| = 1. Solved by the direct boundary-element
method with constant elements: ½ φ_i + Σ_j H_ij φ_j = Σ_j G_ij q_j, G = −ln(r)/(2π),
collocated at the elements' midpoints, 16-point Gauss quadrature off the diagonal and the
exact integral of ln r on it. With 200 elements on the circle and a box 8 m wide and deep
around it, Ca reads 1.0003 (the unbounded 1). Needs numpy.
"""

import argparse

import numpy as np


def elements(width, depth, centre, radius, size):
    """The boundary's straight elements (start, end) and kinds: 0 the free surface (φ = 0),
    1 a wall or the floor (∂φ/∂n = 0), 2 the circle. The tank runs anticlockwise and the circle
    clockwise, so that the normal to the right of each element points out of the water."""
    starts, ends, kinds = [], [], []

    def side(a, b, kind, count):
        a, b = np.asarray(a, float), np.asarray(b, float)
        for k in range(count):
            starts.append(a + (b - a) * k / count)
            ends.append(a + (b - a) * (k + 1) / count)
            kinds.append(kind)

    def along(a, b):
        return int(np.ceil(np.hypot(b[0] - a[0], b[1] - a[1]) / size))

    corners = [(0, 0), (width, 0), (width, depth), (0, depth)]
    for k, kind in enumerate([1, 1, 0, 1]):
        a, b = corners[k], corners[(k + 1) % 4]
        side(a, b, kind, along(a, b))
    count = int(np.ceil(2 * np.pi * radius / size))
    angles = -np.linspace(0, 2 * np.pi, count + 1)
    for k in range(count):
        for point, angle in ((starts, angles[k]), (ends, angles[k + 1])):
            point.append(np.array(centre) + radius * np.array([np.cos(angle), np.sin(angle)]))
        kinds.append(2)
    return np.array(starts), np.array(ends), np.array(kinds)


def added_mass(width, depth, centre, radius, direction, size):
    """Ca of the circle moving along the unit vector `direction`, elements `size` long."""
    a, b, kind = elements(width, depth, centre, radius, size)
    tangent = b - a
    length = np.linalg.norm(tangent, axis=1)
    tangent /= length[:, None]
    normal = np.stack([tangent[:, 1], -tangent[:, 0]], 1)
    mid = 0.5 * (a + b)
    nodes, weights = np.polynomial.legendre.leggauss(16)
    g = np.zeros((len(mid), len(mid)))
    h = np.zeros_like(g)
    for s, w in zip(nodes, weights):
        y = mid + tangent * (0.5 * s * length)[:, None]
        d = y[None, :, :] - mid[:, None, :]
        r2 = (d**2).sum(2)
        np.fill_diagonal(r2, 1.0)
        jacobian = (0.5 * w * length)[None, :]
        g -= np.log(r2) / (4 * np.pi) * jacobian
        h -= (d * normal[None, :, :]).sum(2) / r2 / (2 * np.pi) * jacobian
    np.fill_diagonal(g, -length * (np.log(length / 2) - 1) / (2 * np.pi))
    np.fill_diagonal(h, 0.5)
    body = kind == 2
    q = np.where(body, normal @ np.asarray(direction, float), 0.0)
    # Unknowns: φ on the walls and the circle, q = ∂φ/∂n on the free surface.
    phi_unknown = kind != 0
    matrix = np.where(phi_unknown[None, :], h, -g)
    x = np.linalg.solve(matrix, g[:, body] @ q[body])
    phi = np.where(phi_unknown, x, 0.0)
    flux = -(normal[body] @ np.asarray(direction, float)) * length[body]
    return -np.sum(phi[body] * flux) / (np.pi * radius**2)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    for name in ["width", "depth", "cx", "cy", "radius"]:
        parser.add_argument(name, type=float)
    args = parser.parse_args()
    centre = (args.cx, args.cy)
    for size in [args.radius * np.pi / 100, args.radius * np.pi / 200]:
        ca = [added_mass(args.width, args.depth, centre, args.radius, e, size) for e in [(1, 0), (0, 1)]]
        print(f"elements {size:.2e} m: Ca along x {ca[0]:.4f}, along y {ca[1]:.4f}")


if __name__ == "__main__":
    main()
