"""What the benchmarks in bench/ share: result records, the machine's description, the script
entry point, the report and its plots, and the DDS pipeline harness.

Imported with bench/ on ``sys.path``: a script in bench/ has it there already, and ``sailor bench``
puts it there. Nothing here is part of the installed package.
"""
