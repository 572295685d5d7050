"""The ``kinema`` command line: one module per verb group, each thin (parse → library → print)."""
