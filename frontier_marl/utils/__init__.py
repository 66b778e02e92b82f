"""Small helpers every layer uses: value checks, the JSON writer, the progress bar,
the parsing of ``--set KEY=VALUE`` options."""
