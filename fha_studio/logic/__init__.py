"""Logic layer: sizing, procedures, recording, analysis. No Qt."""
