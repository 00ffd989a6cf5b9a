"""The model check as a page of the main window: the same workflow as ``fha-studio discrepancy``,
with each step's plots."""
