"""The scope: live view, trace capture, built-in tests, recording (Qt, pyqtgraph)."""
