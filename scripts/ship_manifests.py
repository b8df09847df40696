"""Regenerate the shipped manifests of the generated sets (maintainers, after a renderer change).

For every ``data_manifests/synth-*.yaml``: generate its world (the manifest's seed, style and
variant with the current renderer and spec defaults), then rewrite the manifest with the new
spec, key and file sums, keeping its name and description. Run by hand:

    python scripts/ship_manifests.py [--jobs 2] [NAME ...]

``--add STYLE`` also writes the six variants of a style that has no shipped manifests yet
(``synth-<style>-<variant>``, seed 0, the default grid and cameras).
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

from homebench.data.catalog import SHIPPED_MANIFESTS
from homebench.data.generate import MANIFEST_NAME, generate
from homebench.data.manifest import load_manifest
from homebench.data.synth.spec import VARIANTS, WorldSpec
from homebench.fileio import write_text_atomic


def _ship(spec: WorldSpec, name: str, description: str, jobs: int) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        folder = generate(spec, Path(tmp) / name, jobs, name, description=description)
        text = (folder / MANIFEST_NAME).read_text(encoding="utf-8")
    write_text_atomic(SHIPPED_MANIFESTS / f"{name}.yaml", text)
    print(f"{name}: {spec.key()}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", help="manifest names (default: every synth-*)")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--add", metavar="STYLE", help="write the variants of a new style")
    args = parser.parse_args()
    if args.add:
        for variant in VARIANTS:
            spec = WorldSpec(style=args.add, variant=variant)
            name = f"synth-{args.add}-{variant}"
            description = (
                f"Generated world, style '{args.add}', variant '{variant}' (seed 0, the same "
                "place in every variant). 10 x 17 positions 0.30 m apart; raw 752 x 564 and "
                "unfolded panoramas. File sums as generated on the reference machine."
            )
            _ship(spec, name, description, args.jobs)
        return
    paths = sorted(SHIPPED_MANIFESTS.glob("synth-*.yaml"))
    for path in paths:
        if args.names and path.stem not in args.names:
            continue
        manifest = load_manifest(path)
        old = manifest.generator.spec
        spec = WorldSpec(seed=old.seed, style=old.style, variant=old.variant)
        _ship(spec, path.stem, manifest.description, args.jobs)


if __name__ == "__main__":
    main()
