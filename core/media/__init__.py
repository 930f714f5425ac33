"""Participating media (compendium item 54): homogeneous absorption and scattering, the
Henyey–Greenstein phase function, spectral free-flight sampling and transmittance
(kernel.py).
"""
