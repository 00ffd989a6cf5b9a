"""Fixtures of the catalogue tests."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def known_ids():
    from fha_studio.catalog import discrepancies

    return {d.id for d in discrepancies()}
