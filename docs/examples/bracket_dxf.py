"""Writes docs/examples/bracket.dxf, the drawing of the tutorial "From a CAD file to a report"
(units: mm): a lug 80 mm long and 40 mm high, its left edge on the layer ``clamp``, the rest
of its outline (three lines and the half circle of its round end, an ARC) on ``edge``, and
a pin hole of radius 8 mm (a CIRCLE) on ``pin``. Run it to make the file again:

    python docs/examples/bracket_dxf.py
"""

import pathlib

import ezdxf

LENGTH, HEIGHT, PIN_RADIUS = 60.0, 40.0, 8.0      # straight part, height, pin hole (mm)
END = (LENGTH, HEIGHT / 2)                         # centre of the round end and of the pin


def write_bracket(path):
    """Write the bracket's drawing to ``path`` (a DXF R2010 file)."""
    doc = ezdxf.new("R2010", units=ezdxf.units.MM)
    for layer in ("clamp", "edge", "pin"):
        doc.layers.add(layer)
    msp = doc.modelspace()
    msp.add_line((0, 0), (0, HEIGHT), dxfattribs={"layer": "clamp"})
    msp.add_line((0, HEIGHT), (LENGTH, HEIGHT), dxfattribs={"layer": "edge"})
    msp.add_arc(END, HEIGHT / 2, -90, 90, dxfattribs={"layer": "edge"})   # counter-clockwise
    msp.add_line((LENGTH, 0), (0, 0), dxfattribs={"layer": "edge"})
    msp.add_circle(END, PIN_RADIUS, dxfattribs={"layer": "pin"})
    doc.saveas(path)


if __name__ == "__main__":
    target = pathlib.Path(__file__).with_name("bracket.dxf")
    write_bracket(target)
    print(f"wrote {target}")
