"""The tool's version read from its metadata's headers alone (``conformance.version_of``,
issue 22: the whole metadata, the README among it, was parsed as an e-mail message in every
run) is what importlib.metadata reads, for every installed distribution and for metadata
whose version header is folded, repeated, spaced or missing."""

from __future__ import annotations

import importlib.metadata as metadata

import pytest

import conformance
from conformance import version_of


class _Metadata(metadata.Distribution):
    """A distribution whose metadata is the text given."""

    def __init__(self, text: str) -> None:
        self.text = text

    def read_text(self, filename: str) -> str | None:
        return self.text if filename == "METADATA" else None

    def locate_file(self, path):  # pragma: no cover - never asked here
        raise NotImplementedError


def test_every_installed_distribution_reads_as_importlib_reads_it() -> None:
    seen = 0
    for dist in metadata.distributions():
        assert version_of(dist) == dist.version, dist.metadata["Name"]
        seen += 1
    assert seen > 10
    assert conformance.__version__ == metadata.version("sdi12-conform")


@pytest.mark.parametrize(
    "text",
    [
        "Metadata-Version: 2.1\nName: x\nVersion: 1.2.3\n\nVersion: 9\n",
        "Metadata-Version: 2.1\nName: x\nVersion: 1.2.3\r\n\r\nVersion: 9\r\n",
        "Name: x\nversion: 1.0\n\nbody",
        "Name: x\nVersion:1.0\n\nbody",
        "Name: x\nVersion: 1.0  \n\nbody",
        "Name: x\nVersion: 1.0\n 2\n\nbody",
        "Name: x\nSummary: a\n  folded\nVersion: 3\nKeywords: a\n\tb\n\nbody",
        "Name: x\nVersion: 1\nVersion: 2\n\nbody",
        "Name: x\n\nVersion: 2\n",
        "Name: x\nVersion: \n\nbody",
        "",
    ],
)
def test_odd_metadata_reads_as_importlib_reads_it(text: str) -> None:
    dist = _Metadata(text)
    assert version_of(dist) == dist.version


class _Unparsed(_Metadata):
    """Metadata that must not be parsed whole (the cost ``version_of`` saves)."""

    @property
    def metadata(self):
        raise AssertionError("the whole metadata was parsed")


def test_a_plain_version_header_is_read_without_parsing_the_description() -> None:
    body = "Version: 0.0\n" * 50_000  # a description mentioning versions, as a README may
    assert version_of(_Unparsed(f"Name: x\nVersion: 1.2.3\nSummary: s\n\n{body}")) == "1.2.3"
