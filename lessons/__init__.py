"""The course's lessons, one runnable module each.

Run one in a window with ``python -m lessons.<module>``, or headless with
``python -m lessons.<module> --headless --out FILE.png``. Lessons use only
glsandbox's public API.
"""
