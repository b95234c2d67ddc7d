"""Build every FMU of the project into ``models/``.

Usage: ``python build_fmu.py [--dest models] [NAME ...]``. Each model is
``fmu_src/<Name>/<Name>.py``; pythonfmu packs it with the ``driveline`` package and
the adapter, then the model description is completed from the model's spec.
"""

from __future__ import annotations

import argparse
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent
FMU_SRC = ROOT / "fmu_src"
sys.path.insert(0, str(FMU_SRC))
sys.path.insert(0, str(ROOT))

from pythonfmu import FmuBuilder  # noqa: E402

from driveline.catalog import MODELS  # noqa: E402
from model_description import complete_fmi2  # noqa: E402

REQUIREMENTS = "numpy>=1.24\nscipy>=1.10\n"


def _rewrite_zip(path: Path, replace: dict[str, bytes]) -> None:
    """Rewrite ``path`` with some members replaced or added."""
    with zipfile.ZipFile(path) as source:
        members = {info.filename: source.read(info) for info in source.infolist()}
    members.update(replace)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as target:
        for name, data in members.items():
            target.writestr(name, data)


def build_fmi2(name: str, dest: Path) -> Path:
    """Build ``<dest>/<name>.fmu`` (FMI 2.0 co-simulation)."""
    fmu = FmuBuilder.build_FMU(
        FMU_SRC / name / f"{name}.py",
        dest=dest,
        project_files=[ROOT / "driveline", FMU_SRC / "fmi2_slave.py"],
        canGetAndSetFMUstate=True,
        canSerializeFMUstate=True,
    )
    with zipfile.ZipFile(fmu) as archive:
        xml = archive.read("modelDescription.xml")
    _rewrite_zip(
        Path(fmu),
        {
            "modelDescription.xml": complete_fmi2(xml, MODELS[name].spec),
            "resources/requirements.txt": REQUIREMENTS.encode(),
        },
    )
    return Path(fmu)


def build_all(dest: Path = ROOT / "models", names: list[str] | None = None) -> list[Path]:
    return [build_fmi2(name, dest) for name in (names or list(MODELS))]


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", help=f"models to build (default: all of {', '.join(MODELS)})")
    parser.add_argument("--dest", type=Path, default=ROOT / "models")
    args = parser.parse_args(argv)
    for path in build_all(args.dest, args.names or None):
        print(path.relative_to(ROOT) if path.is_relative_to(ROOT) else path)


if __name__ == "__main__":
    main()
