"""The ``sailor`` command-line tool: one module per subcommand, each with add_parser() and run()."""
