"""Where a person looks at a lesson: the window and its keys (``window``), the live controls
(``controls``, their model; ``panel``, their Dear ImGui drawing), reload on save
(``file_watch``), and the notebook helpers (``notebook``, ``notebook_view``).
"""
