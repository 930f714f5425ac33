"""Operators."""
from . import compare, cornell, lux, render

classes = (render.SPECTRALGI_OT_render, cornell.SPECTRALGI_OT_add_cornell_box, compare.SPECTRALGI_OT_compare_cycles) \
    + lux.classes
