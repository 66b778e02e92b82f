"""Small helpers every layer uses: value checks, the JSON writer, the progress bar."""
