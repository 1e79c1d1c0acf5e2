"""Meshes beyond the built-in shapes: model files and the models made without one.

``load`` reads a model file through trimesh (``glsandbox.load_mesh``, ``glsandbox.load_model``),
after ``precheck`` has checked its text and the memory it needs; ``normals`` makes
crease-angle normals, ``looks`` a file's materials and what of it is not drawn, and
``generate`` a rock, a terrain or an icosphere (``glsandbox.meshgen``).
"""
