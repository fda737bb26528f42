"""Where a data set's website files come from: a folder in the ILP layout, or the same
files served over HTTP (as the course served them).

Both answer ``text(relative_path)`` with the file's text and name it in errors by its
real path or URL, so a missing ``words/.../details.json`` reads as that file.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from skyroute.errors import InputFormatError, OptionError, SkyrouteError
from skyroute.files import need_folder, read_text, strip_bom

TIMEOUT = 5.0  # seconds per request


@dataclass(frozen=True)
class DirSource:
    """``root/website/<path>`` on disk; orders from ``root/database/*.csv``."""

    root: Path

    def where(self, path: str) -> str:
        return str(self.root / "website" / path)

    def text(self, path: str) -> str:
        p = self.root / "website" / path
        if not p.is_file():
            raise InputFormatError(p, "no such file")
        return read_text(p)  # a byte-order mark (Notepad, Excel) read past


@dataclass(frozen=True)
class HttpSource:
    """``base/<path>`` over HTTP (httpx, one client, a timeout per request)."""

    base: str

    def where(self, path: str) -> str:
        return f"{self.base.rstrip('/')}/{path}"

    def text(self, path: str) -> str:
        import httpx

        url = self.where(path)
        try:
            r = _client().get(url, timeout=TIMEOUT)
        except httpx.HTTPError as exc:
            raise SkyrouteError(f"{url}: cannot reach the data server "
                                f"({type(exc).__name__}: {exc})") from None
        if r.status_code == 404:
            raise InputFormatError(url, "no such file (HTTP 404)")
        if r.status_code != 200:
            raise SkyrouteError(f"{url}: HTTP {r.status_code}")
        return strip_bom(r.text)


_CLIENT = None


def _client():
    global _CLIENT
    if _CLIENT is None:
        import httpx

        _CLIENT = httpx.Client()
    return _CLIENT


def open_source(data: Path | None, source: str | None) -> DirSource | HttpSource:
    """The one source a caller names: a folder ``data`` or a URL ``source``."""
    if (data is None) == (source is None):
        raise OptionError("give exactly one of data=DIR and source=URL",
                          param=("data", "source"))
    if source is not None:
        if not source.startswith(("http://", "https://")):
            raise OptionError(f"source={source!r}: expected an http:// or https:// URL",
                              param="source")
        return HttpSource(source)
    if not (need_folder(data) / "website").is_dir():
        raise InputFormatError(data, "not a data folder: no website/ inside (the ILP layout)")
    return DirSource(data)
