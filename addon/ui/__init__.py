"""User interface: panels mirror the property modules."""
from . import light_panel, lux_panel, material_panel, render_panel

classes = render_panel.classes + light_panel.classes + material_panel.classes + lux_panel.classes
