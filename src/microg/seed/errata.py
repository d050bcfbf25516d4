"""The errata of the seed report: each printed value beside microg's, and the reason.

Built from the comparisons of a reproduction (:mod:`microg.seed.comparison`) and its recomputed
tables (:mod:`microg.seed.tables`): one entry per printed value that differs from its
recomputation by more than its tolerance, with the computed reason (for example a printed
libration acceleration is called "twice Eq. 3.2" only when it is twice the recomputed value
within the tolerance), then the OCR corrections, what Table 4 leaves out, and the errors of
the text.  Every entry has an id (``E1``, ``E2``, ...) that the comparisons link to.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

from microg.seed.comparison import CASE_NAMES, Comparison
from microg.seed.ioc import printed
from microg.seed.tables import Table4Case

__all__ = ["ErrataEntry", "build_errata"]


@dataclass(frozen=True)
class ErrataEntry:
    """One printed value beside its recomputation, and why they differ.

    Attributes
    ----------
    where, quantity : str
    printed, recomputed : float or None
        In the unit named in ``quantity`` (None for an equation or a missing value).
    rel_diff : float or None
        (recomputed - printed) / |printed|.
    reason : str
    id : str
        ``E1``, ``E2``, ... in the order of the table.
    cause : str
        Short cause (the agreement summary groups differences by it).
    tolerance : float or None
        The comparison's tolerance, absolute (None when not a compared value).
    """

    where: str
    quantity: str
    printed: float | None
    recomputed: float | None
    rel_diff: float | None
    reason: str
    id: str = ""
    cause: str = ""
    tolerance: float | None = None


def build_errata(
    comparisons: list[Comparison], *, cases: Sequence[str], table4: Mapping[str, Table4Case]
) -> tuple[list[ErrataEntry], list[Comparison]]:
    """The errata, and the comparisons with their errata ids set.

    Parameters
    ----------
    comparisons : list of Comparison
        Every printed value compared (:func:`microg.seed.agreement.build_comparisons`).
    cases : sequence of str
        The Appendix C cases recomputed (keys of :data:`microg.seed.ioc.CASES`), in order:
        each brings its OCR corrections.
    table4 : mapping
        Case -> its recomputed Table 4 (the rigid translation and libration, g).
    """
    out: list[ErrataEntry] = []
    linked: list[Comparison] = []
    c = printed()["constants"]

    def add(entry: ErrataEntry) -> str:
        eid = f"E{len(out) + 1}"
        out.append(replace(entry, id=eid))
        return eid

    for cmp in comparisons:
        if cmp.agrees:
            linked.append(cmp)
            continue
        eid = add(
            ErrataEntry(
                cmp.where,
                cmp.quantity,
                cmp.printed,
                cmp.recomputed,
                cmp.rel_diff,
                cmp.reason,
                cause=cmp.cause,
                tolerance=cmp.tolerance,
            )
        )
        linked.append(replace(cmp, erratum=eid))
    for case in cases:
        for (i, j), ocr in _ocr(case).items():
            add(
                ErrataEntry(
                    f"Appendix {CASE_NAMES[case]}",
                    f"m{i + 1}{j + 1} as read",
                    ocr[0],
                    ocr[1],
                    (ocr[1] - ocr[0]) / abs(ocr[0]),
                    "OCR damage: the printed value is not positive definite; the value of C-1 "
                    "and C-3 for this orbiter-independent element is used",
                    cause="OCR damage",
                )
            )
    if table4:
        xo = table4.get("xz_orbiter") or next(iter(table4.values()))
        add(
            ErrataEntry(
                "Eq. 3.1 / Table 4",
                "rigid translation acceleration during the push (g)",
                None,
                xo.rigid_translation_accel_g,
                None,
                "Eq. 3.1 sums the elastic modes only; the whole station accelerates at f0/m11 "
                "while the crew pushes, more than either bending mode, and rigid rotation adds "
                f"{xo.libration.exact_peak_accel_g:.3g} g at the lab (vs the libration "
                f"{xo.libration.accel_g:.3g} g of Eq. 3.2)",
                cause="left out by the report",
            )
        )
    ek = 4 * c["EI"] / (3 * c["l_s"] ** 3)
    add(
        ErrataEntry(
            "Appendix B-1",
            "k44 (lbf/ft)",
            ek,
            2 * ek,
            1.0,
            "k44 = 4EI/(3 l_s^3) is one cantilever, but m44 counts the mass of both boom halves; "
            "two half-booms bending together have twice the stiffness. The reproduction uses the "
            "report's k44; the model-based analyses use the physical two-sided boom",
            cause="error in the text",
        )
    )
    for where, text in _TEXT_ERRATA:
        add(ErrataEntry(where, text[0], None, None, None, text[1], cause="error in the text"))
    return out, linked


def _ocr(case: str) -> dict[tuple[int, int], tuple[float, float]]:
    fixes = printed()["appendix_c"][case].get("ocr_corrections", [])
    return {(int(i), int(j)): (float(a), float(b)) for i, j, a, b in fixes}


_TEXT_ERRATA: list[tuple[str, tuple[str, str]]] = [
    ("Eq. 2.15", ("equation", "reads eta'' + w^2 eta = f_a(t), zero initial conditions")),
    ("Eq. 2.17c", ("missing", "derived by superposing ramps and steps (microg.dynamics.crew)")),
    ("Eq. 2.17d", ("cos w(t2 - t13)", "cos w(t - t13)")),
    (
        "Eq. 2.16",
        (
            "landing (f0/t1)(t - t14)",
            "read as a jump to -f0 ramping to 0 at t14 (seed "
            "review); identical to the printed slope when t14 - t13 = t1",
        ),
    ),
    (
        "Eq. 2.19d",
        (
            "missing",
            "derived (microg.dynamics.crew): A = sin wt - sin w(t-t1) + (t1/d) [sin w(t-t13) "
            "- sin w(t-t14)] - w t1 [cos w(t-t1) + cos w(t-t13)], d = t14 - t13",
        ),
    ),
    ("Eq. 2.20b", ("f0/(w^3 t1 M_jj)", "the acceleration scale is f0/(w_j t1 M_jj), as Eq. 3.1")),
    ("Eq. 2.26", ("third element mbar33 w^2", "mbar34 w^2 (from the second row of Eq. 2.24)")),
    ("Eq. 2.33", ("(M/w) sin wt", "theta = H/(I_y w_y) sin w_y t, H the torque impulse")),
    (
        "Eq. 2.27",
        (
            "3 w0^2 (I_y - I_z)",
            "the report's form is used; the complete linearised roll "
            "equation has 4 w0^2 and couples with yaw",
        ),
    ),
    (
        "Appendix B-2",
        (
            "k22 = 3 (mu/R^3)(I_x - I_z)",
            "with psi2 = z/l_k the generalized stiffness needs 1/l_k^2 "
            "(microg.structure.ritz includes it)",
        ),
    ),
    ("Conclusion 7", ("Eq. (4.1)", "Eq. (3.1)")),
    ("Section 3 note 2", ("Table 5", "Table 4")),
]
