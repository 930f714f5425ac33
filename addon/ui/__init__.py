"""User interface: panels mirror the property modules."""
from . import material_panel, render_panel

classes = render_panel.classes + material_panel.classes
