"""plotting stage of microg (see docs/architecture.md)."""
