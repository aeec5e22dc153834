"""Figures (matplotlib). Imported only by users and the CLI, never by the core packages."""
