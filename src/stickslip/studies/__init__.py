"""Studies: computations that answer a question about the models (docs/extensions.md)."""
