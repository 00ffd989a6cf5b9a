"""The model check as a page of the main window (issue 4's GUI view)."""
