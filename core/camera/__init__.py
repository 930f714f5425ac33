"""Camera rays: the pinhole/thin-lens camera vector, pixel filters and ray generation (kernel.py).
"""
