"""Interactive figures (plotly), for notebooks and the HTML reports.

One module per concept: ``model`` (the model in 3-D with a slider over its modes), ``histories``
(quantities against time), ``bands`` (band tables against their limits), ``spectra`` (PSD,
cumulative RMS, spectrogram), ``maps`` (values coloured over the structure in 3-D: locate's
acceleration map, the quasi-steady map); ``common`` holds what they share (float32 data, the
envelope of long lines, the page fragment).  plotly builds every figure and its script: nothing
here writes JavaScript.  The submodules import plotly when a figure is made.
"""

from microg.plotting.analysis import sample_displacements
from microg.plotting.interactive.common import MAX_POINTS, plotly_html
from microg.plotting.interactive.model import MAX_FRAMES, MAX_SAMPLES, modes_3d

__all__ = [
    "MAX_FRAMES",
    "MAX_POINTS",
    "MAX_SAMPLES",
    "modes_3d",
    "plotly_html",
    "sample_displacements",
]
