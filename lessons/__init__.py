"""The course's lessons, one runnable module each.

The repository keeps them here, at its top; installed, they are the package
``glsandbox.lessons`` (the wheel puts this folder inside glsandbox), and a
checkout imports them under that name too, so a user's own ``lessons/``
folder is never confused with them. Run one with ``glsandbox run <name>``,
or headless with ``glsandbox render <name> --out FILE.png`` (also
``python -m glsandbox.lessons.<name>``). Lessons use only glsandbox's public
API.
"""
