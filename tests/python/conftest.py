"""Shared fixtures for the dataset renderer tests (scripts/render-dataset)."""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
SCRIPTS = REPO / "scripts"
sys.path.insert(0, str(SCRIPTS))

from omnislam_render import datasets  # noqa: E402

DATASET_NAMES = list(datasets.DATASETS)


@pytest.fixture(scope="session")
def metadata_dir(tmp_path_factory):
    """Metadata (no images) of every dataset, written once per session."""
    root = tmp_path_factory.mktemp("metadata")
    for name in DATASET_NAMES:
        datasets.build(name, root / name, images=False, log=lambda *_: None)
    return root
