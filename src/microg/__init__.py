"""microg: microgravity environment of an orbiting space station.

The data flow is one-way::

    model -> structure (M, K, point maps) -> modes -> response -> assessment / isolation
          -> report / CLI

See ``docs/architecture.md`` for what each module owns.
"""

from microg.errors import InputError, MicrogError

__all__ = ["InputError", "MicrogError", "__version__"]
__version__ = "0.1.0"
