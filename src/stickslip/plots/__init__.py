"""Every figure of the package, one module per subject (see docs/architecture.md)."""
