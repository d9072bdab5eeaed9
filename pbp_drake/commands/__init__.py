"""The subcommands of `pbp-drake`, one module each (the parser and dispatch are in `cli`)."""
