"""Photometry (compendium items 31–36): radiometric and photometric quantities
(quantities.py), Blender's light units and the emitters' units (units.py), and measured
luminaire profiles, IES LM-63 and EULUMDAT (profiles.py).
"""
