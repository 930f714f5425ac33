"""User interface: panels mirror the property modules."""
from . import render_panel

classes = render_panel.classes
