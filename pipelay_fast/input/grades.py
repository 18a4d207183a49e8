"""Linepipe steel grades: ``pipe.grade`` and the strengths it stands for.

SMYS and SMTS [Pa] are the minimum yield strength R_t0.5 and the minimum
tensile strength R_m of the pipe body, PSL 2, from API Specification 5L,
46th edition (2018), Table 7 (Requirements for the Results of Tensile Tests
for PSL 2 Pipe). A PSL 2 grade carries a delivery-condition letter (R, N, Q
or M: X65Q, X65M); the letter does not change the minimum strengths, so the
grade is named without it. The ISO 3183 name (L + SMYS in MPa) is accepted
too.

Sources checked (figures only):

* the 2018 edition's Table 7 as reproduced in "Pages From API 5L 2018"
  (scribd.com/document/631793234): its title, and the rows L245/B 245 and
  415 MPa, L290/X42 290 and 415, L320/X46 320 and 435;
* the PSL 2 table of tubingchina.com (API-5L-PSL-2-Pipe-Mechanical-
  Properties-Tensile-Yield-Strength-Elongation.htm), the same first rows
  and L360/X52 360 and 460, L390/X56 390 and 490, L415/X60 415 and 520,
  L450/X65 450 and 535, L485/X70 485 and 570, L555/X80 555 and 625 MPa;
* testcert.co/standards/api-5l, the same SMYS and SMTS for B to X80;
* benranderson/wallthick (input_data_files/db_materials.py, at
  52aa5ec), SMYS alone: X52 360, X60 415, X65 450, X70 485 MPa.

The 2018 excerpt stops at X46, so the rows from X52 up are the secondary
sources' (which agree with each other and, on the rows the excerpt has,
with it). Higher grades (X90 and up) were not cross-checked and
are not offered.

The default is X65 (L450), the grade of the paper's scenes: their SMYS of
448 MPa (README, Use) is 65 ksi, X65's minimum yield in US customary units
(api5lx.com/api5lx-grades: X65 65 ksi yield, 77 ksi tensile; pipenostics'
API 5L 2004 table, de-rated in its documented example, gives 448.16 MPa);
the PSL 2 table gives 450 MPa (65,300 psi) and 535 MPa (77,600 psi). The
bundled examples keep the paper's 448 MPa with 531 MPa (77 ksi) as
explicit ``pipe.smys`` and ``pipe.smts``.
"""

from __future__ import annotations

from .validate import choice

__all__ = ["DEFAULT_GRADE", "GRADES", "grade_strengths"]

MPA = 1e6
# API 5L (2018) Table 7, PSL 2 pipe body: grade -> (SMYS, SMTS) [Pa]
_API = {
    "B": (245 * MPA, 415 * MPA),
    "X42": (290 * MPA, 415 * MPA),
    "X46": (320 * MPA, 435 * MPA),
    "X52": (360 * MPA, 460 * MPA),
    "X56": (390 * MPA, 490 * MPA),
    "X60": (415 * MPA, 520 * MPA),
    "X65": (450 * MPA, 535 * MPA),
    "X70": (485 * MPA, 570 * MPA),
    "X80": (555 * MPA, 625 * MPA),
}
# the ISO 3183 name of each: L and the SMYS in MPa
_ISO = {f"L{round(smys / MPA)}": (smys, smts) for smys, smts in _API.values()}
GRADES = {**_API, **_ISO}
DEFAULT_GRADE = "X65"


def grade_strengths(grade: str, path: str = "pipe.grade") -> tuple[float, float]:
    """(SMYS, SMTS) [Pa] of ``grade`` (an API 5L or ISO 3183 name); a name
    not in :data:`GRADES` raises ValueError naming ``path``."""
    choice(path, grade, tuple(GRADES))
    return GRADES[grade]
