"""Appendix 2 shapes against an independent numerical integration of each solid.

The manual's printed formulas have typos (PRINTED_FORMULA_NOTES); the shapes here must match
the mass and the moments of inertia integrated over a fine grid of the actual solid.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fha_studio.logic.sizing import inertia

RHO = 1000.0
SOLID = (110, 110, 110)  # cells per axis for solids curved in every direction
PRISM = (30, 240, 240)  # prisms along x: the section needs the cells, the length does not


def integrate(inside, box, grid=PRISM, extra_axis=None):
    """Mass, centroid and moments about axes through the centroid of {inside(x, y, z)} in box."""
    (x0, x1), (y0, y1), (z0, z1) = box
    xs = [np.linspace(a, b, n, endpoint=False) + (b - a) / n / 2 for (a, b), n in zip(box, grid, strict=True)]
    x, y, z = np.meshgrid(*xs, indexing="ij")
    dv = (x1 - x0) * (y1 - y0) * (z1 - z0) / (grid[0] * grid[1] * grid[2])
    mask = inside(x, y, z)
    x, y, z = x[mask], y[mask], z[mask]
    m = RHO * dv * mask.sum()
    cx, cy, cz = x.mean(), y.mean(), z.mean()
    dx, dy, dz = x - cx, y - cy, z - cz
    out = {
        "m": m,
        "c": (cx, cy, cz),
        "ix": RHO * dv * np.sum(dy**2 + dz**2),
        "iy": RHO * dv * np.sum(dx**2 + dz**2),
        "iz": RHO * dv * np.sum(dx**2 + dy**2),
    }
    if extra_axis is not None:
        u = np.asarray(extra_axis) / np.linalg.norm(extra_axis)
        along = dx * u[0] + dy * u[1] + dz * u[2]
        out["iu"] = RHO * dv * np.sum(dx**2 + dy**2 + dz**2 - along**2)
    return out


def assert_matches(shape, num, rel=0.01):
    assert shape.mass_kg == pytest.approx(num["m"], rel=rel)
    for axis in ("ix", "iy", "iz"):
        value = getattr(shape, f"{axis}_kgm2")
        if value is not None:
            assert value == pytest.approx(num[axis], rel=rel), axis


def test_cylinder():
    r, ln = 0.05, 0.2
    num = integrate(lambda x, y, z: y**2 + z**2 <= r**2, [(-ln / 2, ln / 2), (-r, r), (-r, r)])
    assert_matches(inertia.cylinder(r, ln, RHO), num)


def test_slanted_cylinder():
    r, ln, th = 0.05, 0.2, 30.0
    axis = (math.cos(math.radians(th)), math.sin(math.radians(th)), 0.0)  # z, tilted from the cylinder's x
    num = integrate(
        lambda x, y, z: y**2 + z**2 <= r**2, [(-ln / 2, ln / 2), (-r, r), (-r, r)], extra_axis=axis
    )
    shape = inertia.slanted_cylinder(r, ln, th, RHO)
    assert shape.mass_kg == pytest.approx(num["m"], rel=0.01)
    assert shape.iz_kgm2 == pytest.approx(num["iu"], rel=0.01)
    # at 0 and 90 degrees it is the cylinder's own Ix and Iy
    assert inertia.slanted_cylinder(r, ln, 0, RHO).iz_kgm2 == pytest.approx(
        inertia.cylinder(r, ln, RHO).ix_kgm2
    )
    assert inertia.slanted_cylinder(r, ln, 90, RHO).iz_kgm2 == pytest.approx(
        inertia.cylinder(r, ln, RHO).iy_kgm2
    )


def test_elliptic_cylinder():
    b, c, ln = 0.12, 0.06, 0.2
    num = integrate(
        lambda x, y, z: (2 * y / b) ** 2 + (2 * z / c) ** 2 <= 1,
        [(-ln / 2, ln / 2), (-b / 2, b / 2), (-c / 2, c / 2)],
    )
    assert_matches(inertia.elliptic_cylinder(b, c, ln, RHO), num)


def test_rectangular_pillar():
    a, b, c = 0.3, 0.2, 0.1
    num = integrate(lambda x, y, z: np.ones_like(x, bool), [(0, a), (0, b), (0, c)])
    assert_matches(inertia.rectangular_pillar(a, b, c, RHO), num, rel=2e-3)


def test_circular_pipe():
    r1, r2, ln = 0.05, 0.03, 0.2
    num = integrate(
        lambda x, y, z: (y**2 + z**2 <= r1**2) & (y**2 + z**2 >= r2**2),
        [(-ln / 2, ln / 2), (-r1, r1), (-r1, r1)],
    )
    assert_matches(inertia.circular_pipe(r1, r2, ln, RHO), num)


def test_ball_has_pi_in_its_mass():
    r = 0.05
    num = integrate(lambda x, y, z: x**2 + y**2 + z**2 <= r**2, [(-r, r)] * 3, SOLID)
    shape = inertia.ball(r, RHO)
    assert_matches(shape, num)
    assert shape.mass_kg == pytest.approx(4 / 3 * math.pi * RHO * r**3)
    assert "4/3 ρ R^3" in shape.note  # the printed mass lacks π


def test_cone_about_its_centre_of_gravity():
    r, ln = 0.05, 0.15
    num = integrate(
        lambda x, y, z: np.sqrt(y**2 + z**2) <= r * (1 - x / ln), [(0, ln), (-r, r), (-r, r)], SOLID
    )
    shape = inertia.cone(r, ln, RHO)
    assert_matches(shape, num)
    assert shape.centroid_m[0] == pytest.approx(num["c"][0], rel=0.01)  # G = L/4 from the base
    printed = 3 / 80 * shape.mass_kg * (r**2 + ln**2)
    assert abs(printed / num["iy"] - 1) > 0.1  # the printed Iy is off


def test_square_pipe():
    a, b, d = 0.2, 0.1, 0.02
    h = b / 2

    def inside(x, y, z):
        return ~((np.abs(y) < h - d) & (np.abs(z) < h - d))

    num = integrate(inside, [(-a / 2, a / 2), (-h, h), (-h, h)])
    shape = inertia.square_pipe(a, b, d, RHO)
    assert_matches(shape, num)
    printed_iy = 1 / 6 * shape.mass_kg * (a**2 + (b - d) ** 2 + d**2)
    assert abs(printed_iy / num["iy"] - 1) > 0.1


def test_rhombus_pillar():
    a, b, c = 0.2, 0.12, 0.06
    num = integrate(
        lambda x, y, z: np.abs(2 * y / b) + np.abs(2 * z / c) <= 1,
        [(-a / 2, a / 2), (-b / 2, b / 2), (-c / 2, c / 2)],
    )
    assert_matches(inertia.rhombus_pillar(a, b, c, RHO), num)


def test_hexagonal_pillar():
    a, s = 0.2, 0.05
    k = math.sqrt(3)

    def inside(x, y, z):
        return (np.abs(z) <= k / 2 * s) & (k * np.abs(y) + np.abs(z) <= k * s)

    num = integrate(inside, [(-a / 2, a / 2), (-s, s), (-s, s)])
    assert_matches(inertia.hexagonal_pillar(a, s, RHO), num)


def test_isosceles_triangle_pillar():
    a, b, c = 0.2, 0.1, 0.08
    num = integrate(
        lambda x, y, z: np.abs(y) <= b / 2 * (1 - z / c), [(-a / 2, a / 2), (-b / 2, b / 2), (0, c)]
    )
    shape = inertia.isosceles_triangle_pillar(a, b, c, RHO)
    assert_matches(shape, num)
    assert shape.centroid_m[0] == pytest.approx(num["c"][2], rel=0.01)


def test_right_triangle_pillar():
    a, b, c = 0.2, 0.1, 0.06
    num = integrate(lambda x, y, z: y / b + z / c <= 1, [(-a / 2, a / 2), (0, b), (0, c)])
    shape = inertia.right_triangle_pillar(a, b, c, RHO)
    assert_matches(shape, num)
    assert shape.centroid_m == pytest.approx((num["c"][2], num["c"][1]), rel=0.01)
    assert shape.ix_kgm2 == pytest.approx(2 * (1 / 36) * shape.mass_kg * (b**2 + c**2))  # printed 1/36


def test_every_shape_is_listed_and_rejects_bad_dimensions():
    assert len(inertia.SHAPES) == 12
    with pytest.raises(ValueError, match="radius_m"):
        inertia.cylinder(-0.1, 0.2, RHO)
    with pytest.raises(ValueError, match="inner_radius_m"):
        inertia.circular_pipe(0.05, 0.06, 0.2, RHO)
    with pytest.raises(ValueError, match="wall_m"):
        inertia.square_pipe(0.2, 0.1, 0.06, RHO)


def test_off_axis_and_linear_motion():
    shape = inertia.cylinder(0.05, 0.02, RHO)
    # Ig + m F^2 against the integral about a shifted axis
    f = 0.1
    num = integrate(lambda x, y, z: y**2 + z**2 <= 0.05**2, [(-0.01, 0.01), (-0.05, 0.05), (-0.05, 0.05)])
    assert inertia.off_axis_inertia_kgm2(shape.iy_kgm2, shape.mass_kg, f) == pytest.approx(
        num["iy"] + num["m"] * f**2, rel=0.01
    )
    # a 10 kg table on a 10 mm lead screw
    assert inertia.linear_inertia_kgm2(10, 0.01) == pytest.approx(10 * (0.01 / (2 * math.pi)) ** 2)


def test_materials_table():
    names = [m.name for m in inertia.materials()]
    assert len(names) == 15 and names[0] == "SS45C"
    assert inertia.material("aluminum").density_kg_m3 == 2700
    with pytest.raises(ValueError, match="Duralumin"):
        inertia.material("unobtainium")
