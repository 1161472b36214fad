"""Design tables and design velocities (docs/DESIGN.md, "Gradients"): DesignTable reads the
CSV a CAD program exports for a family of designs (cm_design_table_read); Morpher's
design_velocity and gradient (in morph.py) call cm_design_velocity and cm_design_gradient.
"""
from dataclasses import dataclass
from typing import Any, Dict, List, Tuple

from ._capi import ffi, lib
from ._context import Context
from ._inputs import path_bytes


@dataclass(frozen=True)
class DesignRow:
    """One row of a design table.

    Attributes:
        path: the STEP file (resolved against the table's directory).
        values: parameter name -> value.
        line: its line in the CSV file (1-based).
    """

    path: str
    values: Dict[str, float]
    line: int


class DesignTable:
    """A design table (study.h, cm_design_table_read): the header `step,<p1>,<p2>,...`
    and one row per STEP file with its parameter values, paths relative to the table. Made by
    DesignTable.read."""

    def __init__(self, _ptr: Any = None) -> None:
        """Not for users: a DesignTable comes from DesignTable.read."""
        if _ptr is None or ffi.typeof(_ptr) is not ffi.typeof("cm_design_table *"):
            raise TypeError("cadmorph.DesignTable: made by cadmorph.DesignTable.read")
        self._ptr = _ptr

    @classmethod
    def read(cls, path: Any) -> "DesignTable":
        """Reads a design table (CSV as CAD programs export it: blank lines, CRLF, quoted
        names). Raises BadInputError with path:line for a malformed table, a parameter named
        twice, a value that is not a number or a STEP file that cannot be read."""
        what = "cadmorph.DesignTable.read"
        p = path_bytes(what, "path", path)
        ctx = Context(0, False, what)
        return cls(ctx.create(lib.cm_design_table_read, "cm_design_table",
                              lib.cm_design_table_destroy, p))

    @property
    def parameters(self) -> List[str]:
        """The parameter names, in header order."""
        n = lib.cm_design_table_n_parameters(self._ptr)
        return [ffi.string(lib.cm_design_table_parameter(self._ptr, j)).decode("utf-8", "replace")
                for j in range(n)]

    @property
    def rows(self) -> List[DesignRow]:
        """The rows, in file order."""
        names = self.parameters
        out = []
        for i in range(lib.cm_design_table_n_rows(self._ptr)):
            v = lib.cm_design_table_values(self._ptr, i)
            out.append(DesignRow(
                path=ffi.string(lib.cm_design_table_path(self._ptr, i)).decode("utf-8", "replace"),
                values={name: float(v[j]) for j, name in enumerate(names)},
                line=int(lib.cm_design_table_line(self._ptr, i))))
        return out

    def row_of(self, path: Any) -> int:
        """The index of the row whose STEP file is path (the same file); BadInputError
        (MismatchError) when no row is."""
        what = "cadmorph.DesignTable.row_of"
        p = path_bytes(what, "path", path)
        row = ffi.new("size_t *")
        Context(0, False, what).call(lib.cm_design_table_find, self._ptr, p, row)
        return int(row[0])

    def __repr__(self) -> str:
        return "<cadmorph.DesignTable %d rows, parameters %s>" % (
            lib.cm_design_table_n_rows(self._ptr), ", ".join(self.parameters))


def scheme_name(s: int) -> str:
    """The name of a cm_design_scheme ("central", "forward", "backward", "none")."""
    return ffi.string(lib.cm_design_scheme_name(s)).decode()


def differences(v: Any) -> List[Tuple[str, float, float]]:
    """(scheme, dp_plus, dp_minus) of each parameter of a cm_design_velocities."""
    return [(scheme_name(v.diff[j].scheme), float(v.diff[j].dp_plus), float(v.diff[j].dp_minus))
            for j in range(v.n_parameters)]
