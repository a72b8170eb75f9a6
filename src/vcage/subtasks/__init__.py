"""Stage 5 of the method: candidate subtasks of a scene, their code, simulation-based verification,
and the verified subtask database.

``candidates`` enumerates actionable relations from the catalog's annotations (code as data);
``codegen`` asks a model for a program per candidate (run only in :mod:`vcage.sandbox`); ``calls``
checks every skill call before MuJoCo sees it; ``trial`` runs one seeded trial; ``verify`` runs N
and accepts iff SR > 0.5; ``store`` is the SQLite database (the only importer of ``sqlite3``).
"""
