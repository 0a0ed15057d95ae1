"""`ros2 pkg create`: check the name, print what will be made, write the files.

The console lines are the ones ros2pkg prints ("going to create a new
package", "package name: ...", "creating folder ./my_package", ...), each
path shown as ``os.path.join(destination, ...)`` of the destination as typed.
``base`` lets a caller (the dashboard's Console) resolve a typed destination
against a folder other than the process's working directory.
"""

from __future__ import annotations

import getpass
import os
import re
from collections.abc import Callable
from pathlib import Path

from ros2pkg import templates
from ros2pkg.templates import PackageSpec

BUILD_TYPES = ("cmake", "ament_cmake", "ament_python")
_LICENSE_DIR = Path(__file__).resolve().parent.parent / "licenses"
# SPDX id -> file under licenses/ (the texts ament_copyright also knows).
LICENSES = {
    "Apache-2.0": "Apache-2.0.txt",
    "BSD-3-Clause": "BSD-3-Clause.txt",
    "GPL-3.0-only": "GPL-3.0-only.txt",
    "LGPL-3.0-only": "LGPL-3.0-only.txt",
    "MIT": "MIT.txt",
}
# What catkin_pkg (which colcon uses to read package.xml) accepts without a warning.
_VALID_NAME = re.compile(r"^[a-z][a-z0-9_]*$")

Write = Callable[[str], None]


class CreateError(Exception):
    """ros2pkg's reason for not creating the package, printed as the command's result."""


def check_package_name(name: str) -> None:
    """A ROS package name: lower case letters, digits and underscores, a letter first."""
    if not _VALID_NAME.match(name):
        raise CreateError(
            f'Package name "{name}" does not follow the naming conventions. It should start '
            "with a lower case letter and only contain lower case letters, digits and "
            "underscores."
        )


def default_maintainer() -> tuple[str, str]:
    name = getpass.getuser()
    return name, f"{name}@todo.todo"


def make_spec(
    name: str,
    *,
    build_type: str = "ament_cmake",
    description: str = "TODO: Package description",
    license: str = "TODO: License declaration",
    maintainer_name: str | None = None,
    maintainer_email: str | None = None,
    dependencies: tuple[str, ...] = (),
    node_name: str | None = None,
    package_format: int = 3,
) -> PackageSpec:
    """The package as ros2pkg describes it: the build type decides tool and test dependencies."""
    check_package_name(name)
    if build_type not in BUILD_TYPES:
        raise CreateError(f"unknown build type '{build_type}' (one of {', '.join(BUILD_TYPES)})")
    if build_type == "ament_python" and name == "test":
        raise CreateError(
            "Aborted since 'ament_python' packages can't be named 'test'. Please choose a "
            "different package name."
        )
    for dep in dependencies:
        if not re.match(r"^[A-Za-z0-9][A-Za-z0-9_-]*$", dep):
            raise CreateError(f'Dependency name "{dep}" is not a package name')
    if node_name is not None and not re.match(r"^[A-Za-z_][A-Za-z0-9_]*$", node_name):
        raise CreateError(f"node name '{node_name}' must be a Python identifier")
    default_name, default_email = default_maintainer()
    name_of_maintainer = maintainer_name or default_name
    email = maintainer_email or f"{name_of_maintainer}@todo.todo"
    if maintainer_name and not maintainer_email:
        email = f"{maintainer_name}@todo.todo"
    elif not maintainer_name and not maintainer_email:
        email = default_email
    tool = ("ament_cmake",) if build_type == "ament_cmake" else ()
    tests: tuple[str, ...] = ()
    if build_type == "ament_cmake":
        tests = ("ament_lint_auto", "ament_lint_common")
    elif build_type == "ament_python":
        tests = ("ament_copyright", "ament_flake8", "ament_pep257", "python3-pytest")
    return PackageSpec(
        name=name,
        build_type=build_type,
        description=description,
        license=license,
        maintainer_name=name_of_maintainer,
        maintainer_email=email,
        dependencies=tuple(dependencies),
        node_name=node_name,
        package_format=package_format,
        buildtool_depends=tool,
        test_depends=tests,
    )


def create_package(
    spec: PackageSpec, destination: str = os.curdir, write: Write = print, base: Path | None = None
) -> Path:
    """Write the package under ``destination`` (relative to ``base``); returns its folder.

    Raises CreateError when the folder already exists, with ros2pkg's words.
    """
    root = Path(base) if base is not None else Path.cwd()
    real_destination = (
        (root / destination).resolve() if not os.path.isabs(destination) else (Path(destination))
    )
    shown_package = os.path.join(destination, spec.name)
    package_dir = real_destination / spec.name
    if package_dir.exists():
        raise CreateError(
            f"\nAborted!\nThe directory already exists: {shown_package}\nEither remove the "
            "directory or choose a different destination directory or package name"
        )
    write("going to create a new package")
    write(f"package name: {spec.name}")
    write(f"destination directory: {real_destination}")
    write(f"package format: {spec.package_format}")
    write(f"version: {spec.version}")
    write(f"description: {spec.description}")
    write(f"maintainer: {[f'{spec.maintainer_name} <{spec.maintainer_email}>']}")
    write(f"licenses: {[spec.license]}")
    write(f"build type: {spec.build_type}")
    write(f"dependencies: {list(spec.dependencies)}")
    if spec.node_name:
        write(f"node_name: {spec.node_name}")

    def folder(*parts: str) -> None:
        write(f"creating folder {os.path.join(shown_package, *parts)}")
        package_dir.joinpath(*parts).mkdir(parents=True, exist_ok=True)

    def file(text: str, *parts: str) -> None:
        write(f"creating {os.path.join(shown_package, *parts)}")
        path = package_dir.joinpath(*parts)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")

    write(f"creating folder {shown_package}")
    package_dir.mkdir(parents=True)
    file(templates.package_xml(spec), "package.xml")
    if spec.build_type in ("cmake", "ament_cmake"):
        write("creating source and include folder")
        folder("src")
        folder("include", spec.name)
        file(templates.cmakelists(spec), "CMakeLists.txt")
        if spec.node_name:
            file(templates.node_cpp(spec), "src", f"{spec.node_name}.cpp")
    else:
        write("creating source folder")
        folder(spec.name)
        file(templates.setup_py(spec), "setup.py")
        file(templates.setup_cfg(spec), "setup.cfg")
        folder("resource")
        file("", "resource", spec.name)
        file("", spec.name, "__init__.py")
        folder("test")
        for name, text in templates.test_files().items():
            file(text, "test", name)
        if spec.node_name:
            file(templates.node_py(spec), spec.name, f"{spec.node_name}.py")
    license_file = LICENSES.get(spec.license)
    if license_file is not None:
        (package_dir / "LICENSE").write_text(
            (_LICENSE_DIR / license_file).read_text(encoding="utf-8"), encoding="utf-8"
        )
    else:
        write("")
        write(
            f"[WARNING]: Unknown license '{spec.license}'.  This has been set in the "
            "package.xml, but no LICENSE file has been created."
        )
        write("It is recommended to use one of the ament license identifiers:")
        for known in LICENSES:
            write(known)
    return package_dir
