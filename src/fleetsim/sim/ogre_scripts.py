"""OGRE material scripts, as Gazebo classic reads them for SDF ``<material><script>``.

Scripts (``<material><script><uri>…/materials/scripts</uri>
<uri>…/materials/textures</uri><name>Marker</name>``) are parsed into their block structure
(``material`` > ``technique`` > ``pass`` > ``texture_unit`` > ``texture``), with ``//`` comments
and ``material Child : Parent`` inheritance; the first texture of the first technique is the
one drawn, and a pass's ``diffuse`` gives the colour of an untextured material. The texture
image is looked up as OGRE's resource locations do: in every folder the script's URIs name.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from fleetsim.errors import SimulationError

_TOKEN = re.compile(r"\{|\}|\n|[^\s{}]+")


@dataclass
class OgreBlock:
    """One statement of an OGRE script: its words, its ``{ }`` children and its line."""

    words: list[str]
    line: int
    children: list[OgreBlock] = field(default_factory=list)

    def blocks(self, keyword: str) -> list[OgreBlock]:
        return [c for c in self.children if c.words and c.words[0] == keyword]


@dataclass(frozen=True)
class OgreMaterial:
    """What fleetsim draws of an OGRE ``material``: its texture image name and colour."""

    name: str
    texture: str | None  # image file name as the script writes it
    diffuse: tuple[float, float, float, float] | None
    source: Path
    line: int


_TOKEN = re.compile(r"\{|\}|\n|[^\s{}]+")


def parse_ogre_script(text: str, source: Path) -> list[OgreBlock]:
    """The top-level blocks of an OGRE script (``material``, ``vertex_program``, ...).

    Raises `SimulationError` naming the file and line on unbalanced braces.
    """
    text = re.sub(r"//[^\n]*", "", text)
    root = OgreBlock([], 0)
    stack = [root]
    words: list[str] = []
    line = 1
    start = 1
    for tok in _TOKEN.findall(text):
        if tok == "\n" or tok in "{}":
            if words:
                stack[-1].children.append(OgreBlock(words, start))
                words = []
            if tok == "\n":
                line += 1
            elif tok == "{":
                if not stack[-1].children:
                    raise SimulationError(f"{source}:{line}: '{{' opens a block without a header")
                stack.append(stack[-1].children[-1])
            else:
                if len(stack) == 1:
                    raise SimulationError(f"{source}:{line}: '}}' closes no block")
                stack.pop()
            continue
        if not words:
            start = line
        words.append(tok)
    if words:
        stack[-1].children.append(OgreBlock(words, start))
    if len(stack) > 1:
        raise SimulationError(
            f"{source}:{stack[-1].line}: block '{' '.join(stack[-1].words)}' is never closed"
        )
    return root.children


def _material_name_and_parent(block: OgreBlock) -> tuple[str, str | None]:
    rest = " ".join(block.words[1:])
    name, _, parent = rest.partition(":")
    return name.strip(), parent.strip() or None


def materials_of_script(text: str, source: Path) -> dict[str, OgreMaterial]:
    """Every ``material`` of a script by name, inheritance (``Child : Parent``) resolved within
    the script."""
    raw: dict[str, tuple[OgreBlock, str | None]] = {}
    for block in parse_ogre_script(text, source):
        if block.words[0] == "material" and len(block.words) > 1:
            name, parent = _material_name_and_parent(block)
            raw[name] = (block, parent)
    out: dict[str, OgreMaterial] = {}

    def resolve(name: str, seen: tuple[str, ...] = ()) -> OgreMaterial:
        if name in out:
            return out[name]
        block, parent = raw[name]
        texture, diffuse = _first_texture_and_colour(block, source)
        if parent is not None and parent in raw and parent not in seen:
            base = resolve(parent, (*seen, name))
            texture = texture or base.texture
            diffuse = diffuse or base.diffuse
        out[name] = OgreMaterial(name, texture, diffuse, source, block.line)
        return out[name]

    for name in raw:
        resolve(name)
    return out


def _first_texture_and_colour(block: OgreBlock, source: Path):
    texture, diffuse = None, None
    for technique in block.blocks("technique")[:1]:
        for pas in technique.blocks("pass"):
            for stmt in pas.children:
                if stmt.words[0] == "diffuse" and diffuse is None and len(stmt.words) >= 4:
                    try:
                        v = [float(w) for w in stmt.words[1:5]]
                    except ValueError:
                        raise SimulationError(
                            f"{source}:{stmt.line}: 'diffuse' needs numbers, got "
                            f"'{' '.join(stmt.words[1:])}'"
                        ) from None
                    diffuse = (*v[:3], v[3] if len(v) > 3 else 1.0)
            for unit in pas.blocks("texture_unit"):
                for stmt in unit.blocks("texture"):
                    if texture is None and len(stmt.words) > 1:
                        texture = stmt.words[1]
    return texture, diffuse


def find_ogre_material(name: str, locations: list[Path]) -> OgreMaterial | None:
    """The material ``name`` from the ``.material`` scripts at ``locations`` (folders, whose
    scripts are all read, or script files); None if none defines it."""
    for loc in locations:
        if loc.is_file() and loc.suffix == ".material":
            files = [loc]
        elif loc.is_dir():
            files = sorted(loc.glob("*.material"))
        else:
            continue
        for f in files:
            found = materials_of_script(f.read_text(errors="replace"), f).get(name)
            if found is not None:
                return found
    return None


def texture_file(material: OgreMaterial, folders: list[Path], owner: str) -> Path:
    """The image file of a material's texture, looked up in OGRE's resource folders (the
    script's URIs, the script's own folder and its ``../textures``).

    Raises `SimulationError` naming the image, the material script and ``owner`` (model and
    file) when the image is in none of them.
    """
    assert material.texture is not None
    here = material.source.parent
    folders = [f.parent if f.suffix == ".material" else f for f in folders]
    candidates = [*folders, here, here.parent / "textures"]
    for folder in dict.fromkeys(candidates):
        f = folder / material.texture
        if f.is_file():
            return f
    looked = ", ".join(str(d) for d in dict.fromkeys(candidates))
    raise SimulationError(
        f"{owner}: texture image '{material.texture}' of material '{material.name}' "
        f"({material.source}:{material.line}) not found; looked in {looked}"
    )
