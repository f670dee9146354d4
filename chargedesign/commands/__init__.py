"""One module per CLI command: ``add_arguments(parser)`` and ``run(args) -> int``.

Modules here import only the standard library at the top; library imports go inside ``run``.
"""
