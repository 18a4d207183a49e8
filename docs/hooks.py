"""MkDocs hook: the Markdown files kept beside what they describe (the README,
sweeps/README.md, the benchmark report and its README) become pages of the
site, and every page's relative links, written for reading the repository
on its own, are pointed at the pages they become; the docstrings' reST
roles (mkdocstrings renders ``:func:`name``` as text) read as code.

A link to a file that is a page is rewritten relative to the linking page; a
link to any other file of the repository (a script, an example, a figure a
command writes) keeps its text and loses the link, so that ``mkdocs build
--strict`` sees no link out of the site.
"""

from __future__ import annotations

import posixpath
import re
from pathlib import Path

from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parents[1]
# repository path -> page path in the site (docs/X.md become X.md)
INCLUDED = {
    "README.md": "index.md",
    "sweeps/README.md": "sweeps.md",
    "benchmarks/README.md": "benchmarks/index.md",
    "benchmarks/speed_vs_error.md": "benchmarks/speed_vs_error.md",
    "benchmarks/paper_studies.md": "benchmarks/paper_studies.md",
}
_LINK = re.compile(r"(!?)\[([^\]]*)\]\(([^)\s]+)\)")


def on_files(files, config):
    """Add the included files as pages."""
    for repo_path, page in INCLUDED.items():
        files.append(File.generated(config, page, abs_src_path=str(ROOT / repo_path)))
    return files


def on_page_markdown(markdown, page, config, files):
    """Point the page's relative links at the site's pages."""
    source = _repository_path(page.file.src_uri)
    here = posixpath.dirname(page.file.src_uri)

    def rewrite(match):
        image, text, target = match.groups()
        if re.match(r"[a-z]+:|#", target):
            return match.group(0)
        path, _, anchor = target.partition("#")
        repo = posixpath.normpath(posixpath.join(posixpath.dirname(source), path))
        site = _site_path(repo)
        if site is None:
            return f"*{text}*" if image else f"{text} (`{repo}`)" if text != repo else f"`{repo}`"
        return f"{image}[{text}]({posixpath.relpath(site, here or '.')}" + (
            f"#{anchor})" if anchor else ")")

    return _LINK.sub(rewrite, markdown)


def on_page_content(html, page, config, files):
    """Docstrings' reST roles (``:func:`name```, rendered as ``:func:<code>``)
    as plain code: mkdocstrings renders them as text."""
    return _ROLE.sub(r"\1", html)


_ROLE = re.compile(r":(?:mod|func|class|meth|attr|data|exc|obj):(<code>)~?")


def _repository_path(page: str) -> str:
    for repo, site in INCLUDED.items():
        if site == page:
            return repo
    return f"docs/{page}"


def _site_path(repo: str) -> str | None:
    if repo in INCLUDED:
        return INCLUDED[repo]
    if repo.startswith("docs/") and (ROOT / repo).is_file():
        return repo.removeprefix("docs/")
    return None
