"""Pictures, off-screen: pyvista scenes of models and solutions (`fields`), of 3-D
solutions clipped by a plane (`solid`), matplotlib charts (`charts`), scalar fields at
the nodes (`scalar`: a temperature).

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
from .solid import SOLID_FIELDS, SOLID_LABELS, solution3d
from .fields import (FIELD_LABELS, REGION_COLORS, SOLUTION_FIELDS, PlotError, cells_polydata,
                     model, region_color, solution)
from .scalar import scalar_field
# the scenes' helpers stay reachable as ``cnem.plot.<name>`` (not in __all__)
from .fields import (BAR, BAR_TITLE_GAP, INSTALL_HINT, colour_bar_font,  # noqa: F401
                     font_file, nice_length, nodal_field, use_font)

__all__ = ["model", "solution", "cells_polydata", "region_color", "PlotError", "REGION_COLORS",
           "SOLUTION_FIELDS", "FIELD_LABELS", "offscreen_pyplot", "solution3d", "SOLID_FIELDS",
           "SOLID_LABELS", "scalar_field"]
