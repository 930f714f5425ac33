"""User interface: panels mirror the property modules."""
from . import light_panel, render_panel

classes = render_panel.classes + light_panel.classes
