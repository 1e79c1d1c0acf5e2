"""The grading wing: ``glsandbox check`` and what keeps a submission from reaching anything but its pictures.

- :mod:`~glsandbox.grading.check`: lessons, scene files and folders of submissions against references;
- :mod:`~glsandbox.grading.rubric`: grading files (checks, points, tolerances, hidden checks);
- :mod:`~glsandbox.grading.kinds`: the kinds of check, one registry (a new kind is one entry);
- :mod:`~glsandbox.grading.exercise`, :mod:`~glsandbox.grading.states`: students' functions and
  state tables graded for a class;
- :mod:`~glsandbox.grading.isolate`: a process per submission, the grader's side and the messages;
  :mod:`~glsandbox.grading.zygote`: the grader's handle on the zygote, started ahead of its run;
  :mod:`~glsandbox.grading.portable`: the portable way (a fresh Python per submission);
  :mod:`~glsandbox.grading.runner`: which of the two this machine takes;
- :mod:`~glsandbox.grading.worker`: the zygote, supervisor and renderer;
- :mod:`~glsandbox.grading.warm`: the warm template renderers fork from;
- :mod:`~glsandbox.grading.processes`: a process tree found and killed;
- :mod:`~glsandbox.grading.sandbox`: what a graded submission may read, write and signal;
- :mod:`~glsandbox.grading.layers`: its environment, user and network, and the line naming them;
- :mod:`~glsandbox.grading.reports`: CSV, JSON, HTML, JUnit XML and Gradescope reports;
- :mod:`~glsandbox.grading.gradescope`: the Gradescope autograder bundle;
- :mod:`~glsandbox.grading.shards`: ``check DIR --shard K/N`` and ``glsandbox check merge``.

The wing judges pictures with :mod:`glsandbox.measure.golden`; the rest of
glsandbox uses it only from the commands of :mod:`glsandbox.cli`.
"""
