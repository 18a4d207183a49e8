"""The ``pipe`` table: the line pipe's section, materials, weights and
contents (SI units), validated on construction."""

from __future__ import annotations

import math
from dataclasses import dataclass

from .grades import DEFAULT_GRADE, grade_strengths
from .validate import (
    assign,
    fail,
    flag,
    set_numbers,
)


@dataclass(frozen=True, slots=True)
class Pipe:
    """Pipe section, table ``[pipe]``. EA, EI, GJ come from the steel alone.

    Attributes
    ----------
    outer_diameter : float
        Steel outer diameter Do [m].
    inner_diameter : float
        Steel inner diameter Di [m].
    coating_outer_diameter : float
        Coating outer diameter Dc [m]; default Do (no coating). Sets buoyancy.
    steel_density, coating_density : float
        [kg/m^3]; defaults 7900 and 0.
    youngs_modulus : float
        E [Pa]; default 207e9.
    poisson_ratio : float
        nu [-], in (-1, 0.5); default 0.3.
    grade : str or None
        Linepipe steel grade, API 5L ("B", "X42" ... "X80") or ISO 3183
        ("L245" ... "L555"): SMYS and SMTS from API 5L (2018) Table 7, PSL 2
        (:mod:`pipelay_fast.input.grades`). Default "X65" (450 and 535 MPa) when
        none of grade, smys and smts is given; None when smys (and smts) are.
    smys : float
        Specified minimum yield strength [Pa]; default the grade's. Given
        with ``grade``, it must equal the grade's.
    smts : float or None
        Specified minimum tensile strength [Pa], not below smys; default the
        grade's; None when smys is given without it (then ``[checks]``
        refuse the pipe). Given with ``grade``, it must equal the grade's.
    contents_density : float
        rho_i [kg/m^3]; default 0 (empty).
    contents_level : float
        Height x of the internal free surface Hi [m]; default 0.
    drag_coefficient : float
        Morison drag coefficient C_D [-]; default 1.0.
    hydrodynamic_diameter : float
        Drag diameter D_h [m]; default Dc.
    extensible : bool
        False: inextensible rod (strain held at zero).
    """

    outer_diameter: float
    inner_diameter: float
    coating_outer_diameter: float | None = None
    steel_density: float = 7900.0
    coating_density: float = 0.0
    youngs_modulus: float = 207e9
    poisson_ratio: float = 0.3
    grade: str | None = None
    smys: float | None = None
    smts: float | None = None
    contents_density: float = 0.0
    contents_level: float = 0.0
    drag_coefficient: float = 1.0
    hydrodynamic_diameter: float | None = None
    extensible: bool = True

    def __post_init__(self):
        set_numbers(
            self, "pipe",
            positive=("outer_diameter", "inner_diameter", "steel_density",
                      "youngs_modulus"),
            non_negative=("coating_density", "contents_density", "contents_level",
                          "drag_coefficient"),
            finite=("poisson_ratio",),
        )
        if self.coating_outer_diameter is None:
            assign(self, "coating_outer_diameter", self.outer_diameter)
        set_numbers(self, "pipe", positive=("coating_outer_diameter",))
        self._set_strengths()
        if self.hydrodynamic_diameter is None:
            assign(self, "hydrodynamic_diameter", self.coating_outer_diameter)
        set_numbers(self, "pipe", positive=("hydrodynamic_diameter",))
        assign(self, "extensible", flag("pipe.extensible", self.extensible))
        do = self.outer_diameter
        if self.inner_diameter >= do:
            fail("pipe.inner_diameter", self.inner_diameter,
                 f"must be smaller than pipe.outer_diameter = {do!r}")
        if self.coating_outer_diameter < do:
            fail("pipe.coating_outer_diameter", self.coating_outer_diameter,
                 f"must not be smaller than pipe.outer_diameter = {do!r}")
        if not -1.0 < self.poisson_ratio < 0.5:
            fail("pipe.poisson_ratio", self.poisson_ratio, "must lie in (-1, 0.5)")

    def _set_strengths(self):
        """smys and smts from ``grade`` (X65 when none of the three is given);
        a given strength that differs from the grade's is refused."""
        given = [name for name in ("smys", "smts") if getattr(self, name) is not None]
        if self.grade is None and not given:
            assign(self, "grade", DEFAULT_GRADE)
        if self.grade is not None:
            smys, smts = grade_strengths(self.grade)
            set_numbers(self, "pipe", positive=given)
            for name, value in (("smys", smys), ("smts", smts)):
                if getattr(self, name) is None:
                    assign(self, name, value)
                elif getattr(self, name) != value:
                    fail(f"pipe.{name}", getattr(self, name),
                         f"disagrees with pipe.grade = {self.grade!r} (its {name.upper()} "
                         f"is {value!r} Pa): give pipe.grade or pipe.{name}, not both")
            return
        if self.smys is None:
            raise ValueError("missing key pipe.smys: pipe.smts is given without it "
                             "(give pipe.smys too, or pipe.grade instead)")
        set_numbers(self, "pipe", positive=given)
        if self.smts is not None and self.smts < self.smys:
            fail("pipe.smts", self.smts, f"is below pipe.smys = {self.smys!r}")

    @property
    def wall_thickness(self) -> float:
        """t = (Do - Di)/2 [m]."""
        return 0.5 * (self.outer_diameter - self.inner_diameter)

    @property
    def steel_area(self) -> float:
        """As = pi (Do^2 - Di^2)/4 [m^2]."""
        return math.pi * (self.outer_diameter**2 - self.inner_diameter**2) / 4.0

    @property
    def inner_area(self) -> float:
        """Ai = pi Di^2/4 [m^2]."""
        return math.pi * self.inner_diameter**2 / 4.0

    @property
    def outer_area(self) -> float:
        """Ae = pi Do^2/4 [m^2] (steel outer diameter: the pressure area)."""
        return math.pi * self.outer_diameter**2 / 4.0

    @property
    def displaced_area(self) -> float:
        """pi Dc^2/4 [m^2], the area that sets buoyancy."""
        return math.pi * self.coating_outer_diameter**2 / 4.0

    @property
    def second_moment(self) -> float:
        """I = pi (Do^4 - Di^4)/64 [m^4]."""
        return math.pi * (self.outer_diameter**4 - self.inner_diameter**4) / 64.0

    @property
    def polar_moment(self) -> float:
        """J = 2 I [m^4]."""
        return 2.0 * self.second_moment

    @property
    def bending_stiffness(self) -> float:
        """EI [N m^2]."""
        return self.youngs_modulus * self.second_moment

    @property
    def axial_stiffness(self) -> float:
        """EA [N], steel only."""
        return self.youngs_modulus * self.steel_area

    @property
    def shear_modulus(self) -> float:
        """G = E / (2 (1 + nu)) [Pa]."""
        return self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))

    @property
    def torsional_stiffness(self) -> float:
        """GJ [N m^2]."""
        return self.shear_modulus * self.polar_moment

    @property
    def steel_mass(self) -> float:
        """Steel mass per length [kg/m]."""
        return self.steel_density * self.steel_area

    @property
    def coating_mass(self) -> float:
        """Coating mass per length, rho_c pi (Dc^2 - Do^2)/4 [kg/m]."""
        return self.coating_density * (self.displaced_area - self.outer_area)

    @property
    def contents_mass(self) -> float:
        """Contents mass per length where filled, rho_i Ai [kg/m]."""
        return self.contents_density * self.inner_area
