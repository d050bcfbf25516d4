"""Active isolation (placeholder, filled below)."""
