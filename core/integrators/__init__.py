"""Integrators: the spectral path tracer (path.py: NEE, MIS, Russian roulette; compendium items
24–28, 51, 52), the render loop that prepares a scene and runs passes (render.py), the
first compile spread over two processes (warmup.py, compile_plan.py) and illuminance on
sensor meshes (sensors.py).
"""
