"""Load inertia: FHA-C manual Appendix 2 (shapes, off-axis, linear motion) and materials.

Lengths in m, density in kg/m^3 (specific gravity x 1000), masses in kg, inertia in kg m^2.
Axis names follow the Appendix 2 table: x is the long axis of a pillar or pipe (the axis of a
cylinder), y and z are transverse axes through the centre of gravity.

The printed table has typos; each shape here uses the physically correct formula, and
:data:`PRINTED_FORMULA_NOTES` keeps what the manual prints where it differs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache

from fha_studio.logic.sizing._data import load

# What Appendix 2 prints where it is wrong, and what is used instead.
PRINTED_FORMULA_NOTES: dict[str, str] = {
    "slanted_cylinder": "printed Iz = 1/12 m [R^2 (1 + cos^2 θ) + L^2 sin^2 θ]; "
    "used Iz = 1/12 m [3 R^2 (1 + cos^2 θ) + L^2 sin^2 θ] (θ = 0 must give 1/2 m R^2)",
    "elliptic_cylinder": "mass not printed; used m = π B C L ρ / 4 (B, C: the ellipse's full axes)",
    "ball": "printed m = 4/3 ρ R^3; used m = 4/3 π ρ R^3",
    "cone": "printed Iy = Iz = 3/80 m (R^2 + L^2); used 3/80 m (4 R^2 + L^2) about the centre of gravity",
    "square_pipe": "printed Ix = 1/3 m [B - D]^2 + D^2 and Iy = Iz = 1/6 m [A^2 + (B - D)^2 + D^2]; "
    "used Ix = 1/3 m [(B - D)^2 + D^2] and Iy = Iz = 1/12 m [A^2 + 2 (B - D)^2 + 2 D^2]",
    "right_triangle_pillar": "printed Ix = 1/36 m (B^2 + C^2); used 1/18 m (B^2 + C^2) (polar moment "
    "of a right triangle about its centroid)",
}


@dataclass(frozen=True)
class ShapeInertia:
    """Mass and moments of inertia of one shape about axes through its centre of gravity.

    ``ix_kgm2``/``iy_kgm2``/``iz_kgm2`` are None where the shape gives no such axis (the slanted
    cylinder gives only ``iz``; the ball has one value for every axis). ``centroid_m``: the
    distance G from the stated face to the centre of gravity where the table gives one (cone:
    from the base; triangles: from the base C/3, and for the right triangle also B/3).
    """

    shape: str
    mass_kg: float
    ix_kgm2: float | None
    iy_kgm2: float | None
    iz_kgm2: float | None
    centroid_m: tuple[float, ...] = ()
    note: str = ""


def _positive(**values: float) -> None:
    for name, value in values.items():
        if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a positive number, got {value!r}")


def _shape(
    name: str, m: float, ix: float | None, iy: float | None, iz: float | None,
    centroid: tuple[float, ...] = (),
) -> ShapeInertia:
    return ShapeInertia(name, m, ix, iy, iz, centroid, PRINTED_FORMULA_NOTES.get(name, ""))


def cylinder(radius_m: float, length_m: float, density_kg_m3: float) -> ShapeInertia:
    """Solid cylinder of radius R and length L; x is its axis."""
    _positive(radius_m=radius_m, length_m=length_m, density_kg_m3=density_kg_m3)
    r, ln = radius_m, length_m
    m = math.pi * r**2 * ln * density_kg_m3
    it = m / 4 * (r**2 + ln**2 / 3)
    return _shape("cylinder", m, m * r**2 / 2, it, it)


def slanted_cylinder(
    radius_m: float, length_m: float, angle_deg: float, density_kg_m3: float
) -> ShapeInertia:
    """Solid cylinder whose axis is tilted by θ = ``angle_deg`` from the rotation axis z."""
    _positive(radius_m=radius_m, length_m=length_m, density_kg_m3=density_kg_m3)
    r, ln, th = radius_m, length_m, math.radians(angle_deg)
    m = math.pi * r**2 * ln * density_kg_m3
    iz = m / 12 * (3 * r**2 * (1 + math.cos(th) ** 2) + ln**2 * math.sin(th) ** 2)
    return _shape("slanted_cylinder", m, None, None, iz)


def elliptic_cylinder(b_m: float, c_m: float, length_m: float, density_kg_m3: float) -> ShapeInertia:
    """Cylinder of elliptic section, full axes B (along y) and C (along z), length L along x."""
    _positive(b_m=b_m, c_m=c_m, length_m=length_m, density_kg_m3=density_kg_m3)
    b, c, ln = b_m, c_m, length_m
    m = math.pi * b * c * ln * density_kg_m3 / 4
    return _shape(
        "elliptic_cylinder",
        m,
        m / 16 * (b**2 + c**2),
        m / 4 * (c**2 / 4 + ln**2 / 3),
        m / 4 * (b**2 / 4 + ln**2 / 3),
    )


def rectangular_pillar(a_m: float, b_m: float, c_m: float, density_kg_m3: float) -> ShapeInertia:
    """Rectangular block A (along x) x B (along y) x C (along z)."""
    _positive(a_m=a_m, b_m=b_m, c_m=c_m, density_kg_m3=density_kg_m3)
    a, b, c = a_m, b_m, c_m
    m = a * b * c * density_kg_m3
    return _shape(
        "rectangular_pillar", m, m / 12 * (b**2 + c**2), m / 12 * (c**2 + a**2), m / 12 * (a**2 + b**2)
    )


def circular_pipe(
    outer_radius_m: float, inner_radius_m: float, length_m: float, density_kg_m3: float
) -> ShapeInertia:
    """Round tube, outer radius R1, inner radius R2, length L along x."""
    _positive(outer_radius_m=outer_radius_m, length_m=length_m, density_kg_m3=density_kg_m3)
    r1, r2, ln = outer_radius_m, inner_radius_m, length_m
    if not (0 <= r2 < r1):
        raise ValueError(f"inner_radius_m must be >= 0 and below outer_radius_m ({r1}), got {r2!r}")
    m = density_kg_m3 * math.pi * (r1**2 - r2**2) * ln
    it = m / 4 * ((r1**2 + r2**2) + ln**2 / 3)
    return _shape("circular_pipe", m, m / 2 * (r1**2 + r2**2), it, it)


def ball(radius_m: float, density_kg_m3: float) -> ShapeInertia:
    """Solid sphere of radius R (the same about every axis through its centre)."""
    _positive(radius_m=radius_m, density_kg_m3=density_kg_m3)
    m = 4 / 3 * math.pi * density_kg_m3 * radius_m**3
    i = 2 / 5 * m * radius_m**2
    return _shape("ball", m, i, i, i)


def cone(radius_m: float, length_m: float, density_kg_m3: float) -> ShapeInertia:
    """Solid cone, base radius R, height L along x; G = L/4 from the base."""
    _positive(radius_m=radius_m, length_m=length_m, density_kg_m3=density_kg_m3)
    r, ln = radius_m, length_m
    m = density_kg_m3 / 3 * math.pi * r**2 * ln
    it = 3 / 80 * m * (4 * r**2 + ln**2)
    return _shape("cone", m, 3 / 10 * m * r**2, it, it, (ln / 4,))


def square_pipe(length_m: float, side_m: float, wall_m: float, density_kg_m3: float) -> ShapeInertia:
    """Square tube: length A along x, outer side B, wall thickness D."""
    _positive(length_m=length_m, side_m=side_m, wall_m=wall_m, density_kg_m3=density_kg_m3)
    a, b, d = length_m, side_m, wall_m
    if not d < b / 2:
        raise ValueError(f"wall_m must be below half of side_m ({b / 2}), got {d!r}")
    m = 4 * a * d * (b - d) * density_kg_m3
    it = m / 12 * (a**2 + 2 * (b - d) ** 2 + 2 * d**2)
    return _shape("square_pipe", m, m / 3 * ((b - d) ** 2 + d**2), it, it)


def rhombus_pillar(
    length_m: float, diagonal_b_m: float, diagonal_c_m: float, density_kg_m3: float
) -> ShapeInertia:
    """Rhombic prism: length A along x, diagonals B (along y) and C (along z)."""
    _positive(
        length_m=length_m, diagonal_b_m=diagonal_b_m, diagonal_c_m=diagonal_c_m, density_kg_m3=density_kg_m3
    )
    a, b, c = length_m, diagonal_b_m, diagonal_c_m
    m = a * b * c * density_kg_m3 / 2
    return _shape(
        "rhombus_pillar", m, m / 24 * (b**2 + c**2), m / 24 * (c**2 + 2 * a**2), m / 24 * (b**2 + 2 * a**2)
    )


def hexagonal_pillar(length_m: float, side_m: float, density_kg_m3: float) -> ShapeInertia:
    """Regular hexagonal prism: length A along x, side B."""
    _positive(length_m=length_m, side_m=side_m, density_kg_m3=density_kg_m3)
    a, b = length_m, side_m
    m = 3 * math.sqrt(3) / 2 * a * b**2 * density_kg_m3
    it = m / 12 * (a**2 + 5 / 2 * b**2)
    return _shape("hexagonal_pillar", m, 5 / 12 * m * b**2, it, it)


def isosceles_triangle_pillar(
    length_m: float, base_m: float, height_m: float, density_kg_m3: float
) -> ShapeInertia:
    """Isosceles triangular prism: length A along x, base B along y, height C along z; G = C/3."""
    _positive(length_m=length_m, base_m=base_m, height_m=height_m, density_kg_m3=density_kg_m3)
    a, b, c = length_m, base_m, height_m
    m = a * b * c * density_kg_m3 / 2
    return _shape(
        "isosceles_triangle_pillar",
        m,
        m / 12 * (b**2 / 2 + 2 / 3 * c**2),
        m / 12 * (a**2 + 2 / 3 * c**2),
        m / 12 * (a**2 + b**2 / 2),
        (c / 3,),
    )


def right_triangle_pillar(
    length_m: float, leg_b_m: float, leg_c_m: float, density_kg_m3: float
) -> ShapeInertia:
    """Right-triangular prism: length A along x, legs B along y and C along z; G1 = C/3, G2 = B/3."""
    _positive(length_m=length_m, leg_b_m=leg_b_m, leg_c_m=leg_c_m, density_kg_m3=density_kg_m3)
    a, b, c = length_m, leg_b_m, leg_c_m
    m = a * b * c * density_kg_m3 / 2
    return _shape(
        "right_triangle_pillar",
        m,
        m / 18 * (b**2 + c**2),
        m / 12 * (a**2 + 2 / 3 * c**2),
        m / 12 * (a**2 + 2 / 3 * b**2),
        (c / 3, b / 3),
    )


# Every shape of the Appendix 2 table by name (for a form that lists them).
SHAPES = {
    f.__name__: f
    for f in (
        cylinder,
        slanted_cylinder,
        elliptic_cylinder,
        rectangular_pillar,
        circular_pipe,
        ball,
        cone,
        square_pipe,
        rhombus_pillar,
        hexagonal_pillar,
        isosceles_triangle_pillar,
        right_triangle_pillar,
    )
}


def off_axis_inertia_kgm2(ig_kgm2: float, mass_kg: float, distance_m: float) -> float:
    """I = Ig + m F^2 (Appendix 2 (2)): inertia about an axis at distance F from the centre of gravity."""
    if ig_kgm2 < 0 or mass_kg < 0:
        raise ValueError(f"ig_kgm2 and mass_kg must be >= 0, got {ig_kgm2!r}, {mass_kg!r}")
    return ig_kgm2 + mass_kg * distance_m**2


def linear_inertia_kgm2(mass_kg: float, travel_per_rev_m: float) -> float:
    """I = m (P / 2π)^2 (Appendix 2 (3)): a mass moved P metres per actuator revolution."""
    if mass_kg < 0:
        raise ValueError(f"mass_kg must be >= 0, got {mass_kg!r}")
    return mass_kg * (travel_per_rev_m / (2 * math.pi)) ** 2


@dataclass(frozen=True)
class Material:
    """A load material of Appendix 2's specific-gravity table."""

    name: str
    specific_gravity: float

    @property
    def density_kg_m3(self) -> float:
        """Density in kg/m^3 (specific gravity x 1000)."""
        return self.specific_gravity * 1000.0


@cache
def materials() -> tuple[Material, ...]:
    """The specific-gravity table (resources/sizing/materials.toml), in the manual's order."""
    return tuple(Material(m["name"], float(m["specific_gravity"])) for m in load("materials")["material"])


def material(name: str) -> Material:
    """One material by name (case-insensitive); ValueError listing the known names."""
    for m in materials():
        if m.name.lower() == name.strip().lower():
            return m
    raise ValueError(f"unknown material {name!r}; known: {', '.join(m.name for m in materials())}")
