"""location stage of microg (see docs/architecture.md)."""
