"""Lights: analytic lights (rect, ellipse, point, spot, sun) for next-event estimation and ray
hits, with photometric profiles, in the path kernel (kernel.py). Emissive triangles are
sampled by solid angle (compendium item 22) in core/sampling/sphtri.py and the path kernel.
"""
