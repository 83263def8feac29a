"""Pictures, off-screen: pyvista scenes of models and solutions (`fields`), matplotlib
charts (`charts`).

Neither pyvista nor matplotlib is imported before a picture is drawn, so
``import cnem.plot`` works without them; drawing without them raises `PlotError`
with the command that installs them (``pip install "cnem[plot]"``).

>>> import cnem, cnem.plot                                  # doctest: +SKIP
>>> from cnem.geometry import rectangle                     # doctest: +SKIP
>>> dom = rectangle(1.0, 1.0, cracks=[[[0.0, 0.5], [0.5, 0.5]]])   # doctest: +SKIP
>>> m = cnem.discretize(cnem.nodes.regular(dom, 0.1))      # doctest: +SKIP
>>> cnem.plot.model(m, "cells.png").close()                # doctest: +SKIP
>>> plt = cnem.plot.offscreen_pyplot()                     # doctest: +SKIP
"""

from .charts import offscreen_pyplot
from .fields import (BAR, BAR_TITLE_GAP, FIELD_LABELS, INSTALL_HINT, REGION_COLORS,
                     SOLUTION_FIELDS, PlotError, cells_polydata, colour_bar_font, font_file,
                     model, nice_length, nodal_field, region_color, solution, use_font)

__all__ = ["model", "solution", "cells_polydata", "region_color", "PlotError", "REGION_COLORS",
           "SOLUTION_FIELDS", "FIELD_LABELS", "offscreen_pyplot", "nodal_field", "nice_length",
           "font_file", "use_font", "colour_bar_font", "BAR", "BAR_TITLE_GAP", "INSTALL_HINT"]
