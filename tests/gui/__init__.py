"""GUI tests (a package, so that tests/gui/procedures and tests/procedures do not collide)."""
