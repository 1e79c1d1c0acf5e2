"""The built-in accuracy knobs of ``glsandbox tradeoffs``, one module each.

Each module registers one :class:`~glsandbox.measure.knob.Knob` with
:func:`~glsandbox.measure.knob.register_knob`; :func:`~glsandbox.measure.knob.all_knobs`
imports every module here not starting with ``_``, as lessons are found. A
knob's ``order`` places it in the report. To add a knob, add a module.
"""
