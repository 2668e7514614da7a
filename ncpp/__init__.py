"""ncpp: make existing CNC machine tools more accurate in software.

Data flow (see DESIGN.md): NC text -> Blocks -> motion segments -> passes ->
segments -> writer -> NC text.  Subpackages follow that flow:

program/      lossless blocks, Lark parser, writer, dialects
motion/       modal interpreter and motion segments
passes/       compensation passes, plain functions composed in a tuple
machine/      kinematic chain, 21 geometric errors, non-geometric effects
instruments/  measurement files, forward models, ISO 230-2 / 230-4
identify/     fitting error models from measurements
diagnose/     model-versus-measurement gap analysis
cldata/       APT CL-data reader
export/       controller compensation tables
cli/          the `ncpp` command, one module per subcommand
"""

__version__ = "0.1.0"
