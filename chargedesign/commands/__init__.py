"""The CLI's commands: their arguments in :mod:`.arguments` (light, for ``--help``), and one
module per command with ``run(args) -> int``, imported by :func:`chargedesign.cli.main` only
when that command runs (so each imports its stages at the top).
"""
