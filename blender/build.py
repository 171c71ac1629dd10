"""Builds the Blender extension's zip: `python3 blender/build.py [--program PATH] [--out DIR]`.

The zip holds `blender/hooke_blender/` (its `blender_manifest.toml` at the top) and, with
`--program`, the hooke program as `bin/hooke`, which the extension then runs before looking
for one elsewhere. Install it in Blender with Edit > Preferences > Get Extensions > Install
from Disk (or drag it onto Blender's window).
"""

import argparse
import os
import stat
import sys
import tomllib
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
PACKAGE = os.path.join(HERE, "hooke_blender")


def build(out_dir, program=None):
    """Writes the zip into ``out_dir`` and returns its path."""
    with open(os.path.join(PACKAGE, "blender_manifest.toml"), "rb") as f:
        manifest = tomllib.load(f)
    if program is not None and not (os.path.isfile(program) and os.access(program, os.X_OK)):
        raise SystemExit(f"error: --program {program}: not an executable file")
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, f"hooke-blender-{manifest['version']}.zip")
    tmp = path + ".part"
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        for name in sorted(os.listdir(PACKAGE)):
            full = os.path.join(PACKAGE, name)
            if os.path.isfile(full) and (name.endswith(".py") or name.endswith(".toml")):
                z.write(full, name)
        if program is not None:
            info = zipfile.ZipInfo("bin/hooke")
            info.external_attr = (stat.S_IFREG | 0o755) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            with open(program, "rb") as f:
                z.writestr(info, f.read())
    os.replace(tmp, path)
    return path


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--program", help="the hooke program to bundle (target/release/hooke)")
    parser.add_argument(
        "--out", default=os.path.join(HERE, "..", "target"), help="where the zip goes (target/)"
    )
    args = parser.parse_args()
    print(os.path.normpath(build(args.out, args.program)))


if __name__ == "__main__":
    sys.exit(main())
