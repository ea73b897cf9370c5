#!/usr/bin/env python3
"""Every relative link of README.md, docs/ and the crates' READMEs resolves: the file exists and,
where the link names an anchor, the file has a heading of that anchor (GitHub's rule). Also
every citation of a section of docs/reference.md in the code (`reference.md "Addressing"`) names
one of its headings. Prints each broken link and exits 1 if there is one."""

import pathlib
import re
import subprocess
import sys

root = pathlib.Path(__file__).resolve().parent.parent
LINK = re.compile(r"!?\[(?:[^\]\[]|\[[^\]]*\])*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
FENCE = re.compile(r"^(```|~~~)")


def anchors(path):
    """The anchors GitHub gives the headings of a Markdown file."""
    seen, found = {}, set()
    inside = False
    for line in path.read_text(encoding="utf-8").splitlines():
        if FENCE.match(line):
            inside = not inside
        if inside or not line.startswith("#"):
            continue
        text = line.lstrip("#").strip()
        text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)  # a link in a heading: its text
        slug = re.sub(r"[^\w\- ]", "", text.lower()).replace(" ", "-")
        n = seen.get(slug, 0)
        seen[slug] = n + 1
        found.add(slug if n == 0 else f"{slug}-{n}")
    return found


def links(path):
    inside = False
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        if FENCE.match(line):
            inside = not inside
            continue
        if inside:
            continue
        line = re.sub(r"`[^`]*`", "", line)  # code spans hold no links
        for match in LINK.finditer(line):
            yield number, match.group(1)


pages = [root / "README.md", *sorted((root / "docs").glob("*.md")), *sorted(root.glob("crates/*/README.md"))]
broken = []
cache = {}
for page in pages:
    for number, target in links(page):
        if re.match(r"^[a-z]+:", target):
            continue  # http:, https:, mailto:
        file, _, anchor = target.partition("#")
        resolved = (page.parent / file).resolve() if file else page
        where = f"{page.relative_to(root)}:{number}: {target}"
        if not resolved.exists():
            broken.append(f"{where} (no such file)")
        elif anchor and resolved.suffix == ".md":
            if resolved not in cache:
                cache[resolved] = anchors(resolved)
            if anchor not in cache[resolved]:
                broken.append(f"{where} (no heading #{anchor})")

# Sections of the reference cited by name in the code, the help and the docs.
reference = root / "docs" / "reference.md"
headings = {h.lstrip("#").strip().strip("`") for h in reference.read_text(encoding="utf-8").splitlines() if h.startswith("## ")}
tracked = subprocess.run(["git", "ls-files"], cwd=root, capture_output=True, text=True, check=True).stdout.split()
for name in tracked:
    path = root / name
    if path.suffix not in {".rs", ".wgsl", ".md", ".py", ".sh"} or not path.exists():
        continue
    for number, line in enumerate(path.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
        for section in re.findall(r"reference\.md\)?'?s? \(?\"([^\"]+)\"", line):
            if section not in headings:
                broken.append(f"{name}:{number}: reference.md \"{section}\" (no such section)")

for line in broken:
    print(line)
print(f"check-links: {len(pages)} pages, {len(broken)} broken", file=sys.stderr)
sys.exit(1 if broken else 0)
