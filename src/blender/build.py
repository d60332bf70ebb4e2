#!/usr/bin/env python3
"""Build the pmvc Blender extension: one .zip holding blender_manifest.toml,
__init__.py and the pmvc-cage wheel given, as Blender's "Install from Disk"
takes it (docs/blender.md).

    python3 src/blender/build.py --wheel target/wheels/pmvc_cage-0.1.0-cp39-abi3-linux_x86_64.whl \\
        --out target/blender/pmvc-0.1.0.zip
"""

import argparse
import re
import sys
import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
PLATFORMS = {  # wheel platform tag -> Blender's platform name
    "linux_x86_64": "linux-x64", "manylinux": "linux-x64", "linux_aarch64": "linux-arm64",
    "win_amd64": "windows-x64", "win_arm64": "windows-arm64",
    "macosx_11_0_arm64": "macos-arm64", "macosx_10_12_x86_64": "macos-x64",
}


def platform_of(wheel_name):
    tag = wheel_name[:-len(".whl")].split("-")[-1]
    for prefix, platform in PLATFORMS.items():
        if tag.startswith(prefix) or (prefix == "manylinux" and tag.startswith("manylinux") and tag.endswith("x86_64")):
            return platform
    if tag.startswith("macosx") and tag.endswith("arm64"):
        return "macos-arm64"
    if tag.startswith("macosx"):
        return "macos-x64"
    return None


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--wheel", action="append", required=True, type=Path,
                        help="a pmvc-cage wheel to bundle (repeat for several platforms)")
    parser.add_argument("--out", type=Path, help="the .zip to write (default target/blender/pmvc-VERSION.zip)")
    args = parser.parse_args(argv)

    platforms, names = [], []
    version = None
    for wheel in args.wheel:
        if not wheel.is_file():
            parser.error(f"{wheel}: no such wheel")
        match = re.match(r"pmvc_cage-([^-]+)-", wheel.name)
        if not match:
            parser.error(f"{wheel.name} is not a pmvc-cage wheel (pmvc_cage-VERSION-...whl)")
        with zipfile.ZipFile(wheel) as z:
            if "pmvc/blender/__init__.py" not in z.namelist():
                parser.error(f"{wheel.name} has no pmvc/blender: build it from this repository (pip wheel . -w dist)")
        if version not in (None, match.group(1)):
            parser.error(f"the wheels are of versions {version} and {match.group(1)}")
        version = match.group(1)
        platform = platform_of(wheel.name)
        if platform is None:
            parser.error(f"{wheel.name}: unknown platform tag")
        platforms.append(platform)
        names.append(wheel.name)

    manifest = (HERE / "blender_manifest.toml").read_text()
    manifest = re.sub(r'^version = ".*"$', f'version = "{version}"', manifest, flags=re.M)
    listed = ("wheels = [" + ", ".join(f'"./wheels/{n}"' for n in names) + "]\n"
              + "platforms = [" + ", ".join(f'"{p}"' for p in sorted(set(platforms))) + "]")
    manifest = re.sub(r"^wheels = \[\]$", listed, manifest, flags=re.M)

    out = args.out or HERE.parents[1] / "target" / "blender" / f"pmvc-{version}.zip"
    out.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("blender_manifest.toml", manifest)
        z.write(HERE / "__init__.py", "__init__.py")
        for wheel in args.wheel:
            z.write(wheel, f"wheels/{wheel.name}", compress_type=zipfile.ZIP_STORED)
    print(f"{out}: pmvc {version} for {', '.join(sorted(set(platforms)))}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
