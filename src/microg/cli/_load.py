"""The ``microg`` process's model load: a station read in a child while this one imports.

Reading a station model imports pydantic and validates the TOML (~0.15 s); discretising it
imports scipy and the frame FE (~0.15 s).  Neither needs the other until the structure is
built, so in the ``microg`` process (:func:`microg.cli._startup.is_process`) the station is
read by a forked child (:class:`microg._fork.Forked`) while this process imports the
discretisation's modules, and the two halves run on two cores (issue 8, "Speed of the main
job").  The model is the child's, pickled: the same object, bit for bit.  Anything else (a
modal model, a library caller, one CPU, an error or a warning in the child) loads here, as
:func:`microg.load_model` always does.
"""

from __future__ import annotations

import importlib
from typing import Any

__all__ = ["load_model"]


def load_model(model: str, method: str = "fem", **reader: Any) -> Any:
    """:func:`microg.load_model` of ``model``, read in a child where that is faster.

    Parameters
    ----------
    model : str
        A model file or a shipped model name, as given on the command line.
    method : str
        The discretisation to follow (its modules are imported while the model loads).
    **reader
        ``units``, ``wtmass``, ``points``: as for :func:`microg.load_model`.
    """
    import microg
    from microg.cli._startup import is_process
    from microg.models.load import loads_station

    if not (is_process() and loads_station(model, reader.get("points"))):
        return microg.load_model(model, **reader)
    from microg._fork import Forked
    from microg.structure.discretize import STATION_MODULES

    with Forked.start(microg.load_model, model, **reader) as pending:
        for name in STATION_MODULES.get(method, ()):
            importlib.import_module(name)
        return pending.result()
