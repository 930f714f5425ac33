"""Radiosity for diffuse scenes (Dutré's Global Illumination Compendium, items 53, 55–62).

form_factors.py: the form factors in closed form (items 55, 57, 59; properties 60);
kernel.py: the one kernel (form-factor rows with visibility, item 58; direct light from
analytic lights; ray shooting); meshing.py: patches, refinement, vertex interpolation;
solvers.py: Jacobi, Gauss–Seidel and Southwell on the radiosity and power systems
(items 61–62); solve.py: the scene's solve per wavelength band (item 53), photometry, and
illuminance at any point; gather.py: the final gather, a camera image from a solution.
"""
from .form_factors import (
    differential_form_factor, form_factor_point_polygon, form_factor_polygon_polygon, polygon_area)
from .gather import final_gather
from .gather import render as render_radiosity
from .solve import RadiositySolution, element_form_factors, illuminance_at, lux_integrator, radiosity

__all__ = ["differential_form_factor", "form_factor_point_polygon", "form_factor_polygon_polygon", "polygon_area",
           "element_form_factors", "radiosity", "RadiositySolution", "illuminance_at",
           "lux_integrator", "final_gather", "render_radiosity"]
