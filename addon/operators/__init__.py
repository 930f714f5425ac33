"""Operators."""
from . import cornell, render

classes = (render.SPECTRALGI_OT_render, cornell.SPECTRALGI_OT_add_cornell_box)
