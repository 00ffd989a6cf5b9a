"""The scope's logic: ring buffer, acquisition (polling and drive-side trace), analysis. No Qt."""
