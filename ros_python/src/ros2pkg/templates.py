"""The text of every file `ros2 pkg create` writes, as plain functions of the package.

Written here from the shape of the files Jazzy's ros2pkg produces (package.xml
format 3, setup.py with a console_scripts entry point, setup.cfg with the
underscore spellings ``script_dir``/``install_scripts``, the ament resource
marker, the three linter tests, CMakeLists.txt for ament_cmake), so a learner
following the tutorials sees the same files.
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class PackageSpec:
    """What the command line says about the new package."""

    name: str
    build_type: str = "ament_cmake"
    description: str = "TODO: Package description"
    license: str = "TODO: License declaration"
    maintainer_name: str = "user"
    maintainer_email: str = "user@todo.todo"
    dependencies: tuple[str, ...] = ()
    node_name: str | None = None
    package_format: int = 3
    version: str = "0.0.0"
    buildtool_depends: tuple[str, ...] = field(default=())
    test_depends: tuple[str, ...] = field(default=())


def package_xml(spec: PackageSpec) -> str:
    """package.xml: buildtool, build and test dependencies, then the build type export."""
    fmt = spec.package_format
    lines = [
        '<?xml version="1.0"?>',
        f'<?xml-model href="http://download.ros.org/schema/package_format{fmt}.xsd" '
        'schematypens="http://www.w3.org/2001/XMLSchema"?>',
        f'<package format="{fmt}">',
        f"  <name>{spec.name}</name>",
        f"  <version>{spec.version}</version>",
        f"  <description>{_xml(spec.description)}</description>",
        f'  <maintainer email="{_xml(spec.maintainer_email)}">{_xml(spec.maintainer_name)}'
        "</maintainer>",
        f"  <license>{_xml(spec.license)}</license>",
        "",
    ]
    for tag, names in (
        ("buildtool_depend", spec.buildtool_depends),
        ("depend", spec.dependencies),
        ("test_depend", spec.test_depends),
    ):
        if names:
            lines += [f"  <{tag}>{name}</{tag}>" for name in names] + [""]
    lines += [
        "  <export>",
        f"    <build_type>{spec.build_type}</build_type>",
        "  </export>",
        "</package>",
    ]
    return "\n".join(lines) + "\n"


def _xml(text: str) -> str:
    return (
        text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;")
    )


def _py(text: str) -> str:
    """A value inside single quotes in setup.py."""
    return text.replace("\\", "\\\\").replace("'", "\\'")


def setup_py(spec: PackageSpec) -> str:
    """setup.py: the ament index marker and package.xml as data files, one entry point."""
    entry = (
        f"            '{spec.node_name} = {spec.name}.{spec.node_name}:main'\n"
        if spec.node_name
        else ""
    )
    return (
        "from setuptools import find_packages, setup\n"
        "\n"
        f"package_name = '{spec.name}'\n"
        "\n"
        "setup(\n"
        "    name=package_name,\n"
        f"    version='{spec.version}',\n"
        "    packages=find_packages(exclude=['test']),\n"
        "    data_files=[\n"
        "        ('share/ament_index/resource_index/packages',\n"
        "            ['resource/' + package_name]),\n"
        "        ('share/' + package_name, ['package.xml']),\n"
        "    ],\n"
        "    install_requires=['setuptools'],\n"
        "    zip_safe=True,\n"
        f"    maintainer='{_py(spec.maintainer_name)}',\n"
        f"    maintainer_email='{_py(spec.maintainer_email)}',\n"
        f"    description='{_py(spec.description)}',\n"
        f"    license='{_py(spec.license)}',\n"
        "    tests_require=['pytest'],\n"
        "    entry_points={\n"
        "        'console_scripts': [\n"
        f"{entry}"
        "        ],\n"
        "    },\n"
        ")\n"
    )


def setup_cfg(spec: PackageSpec) -> str:
    """Where setuptools puts the entry-point scripts: lib/<pkg>, where ros2 run looks."""
    return (
        "[develop]\n"
        f"script_dir=$base/lib/{spec.name}\n"
        "[install]\n"
        f"install_scripts=$base/lib/{spec.name}\n"
    )


def node_py(spec: PackageSpec) -> str:
    """The empty executable --node-name asks for: it prints one line."""
    return (
        "def main():\n"
        f"    print('Hi from {spec.name}.')\n"
        "\n"
        "\n"
        "if __name__ == '__main__':\n"
        "    main()\n"
    )


_TEST_HEADER = (
    "# Copyright {year} Open Source Robotics Foundation, Inc.\n"
    "#\n"
    '# Licensed under the Apache License, Version 2.0 (the "License");\n'
    "# you may not use this file except in compliance with the License.\n"
    "# You may obtain a copy of the License at\n"
    "#\n"
    "#     http://www.apache.org/licenses/LICENSE-2.0\n"
    "#\n"
    "# Unless required by applicable law or agreed to in writing, software\n"
    '# distributed under the License is distributed on an "AS IS" BASIS,\n'
    "# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.\n"
    "# See the License for the specific language governing permissions and\n"
    "# limitations under the License.\n"
    "\n"
)


def test_files() -> dict[str, str]:
    """test/test_copyright.py, test_flake8.py, test_pep257.py: the ament linters as tests."""
    copyright_test = (
        _TEST_HEADER.format(year=2015) + "from ament_copyright.main import main\n"
        "import pytest\n"
        "\n"
        "\n"
        "# Remove the `skip` decorator once the source file(s) have a copyright header\n"
        "@pytest.mark.skip(reason='No copyright header has been placed in the generated "
        "source file.')\n"
        "@pytest.mark.copyright\n"
        "@pytest.mark.linter\n"
        "def test_copyright():\n"
        "    rc = main(argv=['.', 'test'])\n"
        "    assert rc == 0, 'Found errors'\n"
    )
    flake8_test = (
        _TEST_HEADER.format(year=2017) + "from ament_flake8.main import main_with_errors\n"
        "import pytest\n"
        "\n"
        "\n"
        "@pytest.mark.flake8\n"
        "@pytest.mark.linter\n"
        "def test_flake8():\n"
        "    rc, errors = main_with_errors(argv=[])\n"
        "    assert rc == 0, \\\n"
        "        'Found %d code style errors / warnings:\\n' % len(errors) + \\\n"
        "        '\\n'.join(errors)\n"
    )
    pep257_test = (
        _TEST_HEADER.format(year=2015) + "from ament_pep257.main import main\n"
        "import pytest\n"
        "\n"
        "\n"
        "@pytest.mark.linter\n"
        "@pytest.mark.pep257\n"
        "def test_pep257():\n"
        "    rc = main(argv=['.', 'test'])\n"
        "    assert rc == 0, 'Found code style errors / warnings'\n"
    )
    return {
        "test_copyright.py": copyright_test,
        "test_flake8.py": flake8_test,
        "test_pep257.py": pep257_test,
    }


def cmakelists(spec: PackageSpec) -> str:
    """CMakeLists.txt of an ament_cmake package (with a C++ node when --node-name is given)."""
    deps = spec.dependencies
    lines = [
        "cmake_minimum_required(VERSION 3.8)",
        f"project({spec.name})",
        "",
        'if(CMAKE_COMPILER_IS_GNUCXX OR CMAKE_CXX_COMPILER_ID MATCHES "Clang")',
        "  add_compile_options(-Wall -Wextra -Wpedantic)",
        "endif()",
        "",
        "# find dependencies",
        "find_package(ament_cmake REQUIRED)",
    ]
    if deps:
        lines += [f"find_package({dep} REQUIRED)" for dep in deps]
    else:
        lines += [
            "# uncomment the following section in order to fill in",
            "# further dependencies manually.",
            "# find_package(<dependency> REQUIRED)",
        ]
    if spec.node_name:
        node = spec.node_name
        lines += [
            "",
            f"add_executable({node} src/{node}.cpp)",
            f"target_include_directories({node} PUBLIC",
            "  $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>",
            "  $<INSTALL_INTERFACE:include/${PROJECT_NAME}>)",
            f"target_compile_features({node} PUBLIC c_std_99 cxx_std_17)  # Require C99 and C++17",
        ]
        if deps:
            lines += ["ament_target_dependencies(", f"  {node}"]
            lines += [f'  "{dep}"' for dep in deps] + [")"]
        lines += ["", f"install(TARGETS {node}", "  DESTINATION lib/${PROJECT_NAME})"]
    lines += [
        "",
        "if(BUILD_TESTING)",
        "  find_package(ament_lint_auto REQUIRED)",
        "  # the following line skips the linter which checks for copyrights",
        "  # comment the line when a copyright and license is added to all source files",
        "  set(ament_cmake_copyright_FOUND TRUE)",
        "  # the following line skips cpplint (only works in a git repo)",
        "  # comment the line when this package is in a git repo and when",
        "  # a copyright and license is added to all source files",
        "  set(ament_cmake_cpplint_FOUND TRUE)",
        "  ament_lint_auto_find_test_dependencies()",
        "endif()",
        "",
        "ament_package()",
    ]
    return "\n".join(lines) + "\n"


def node_cpp(spec: PackageSpec) -> str:
    return (
        "#include <cstdio>\n"
        "\n"
        "int main(int argc, char ** argv)\n"
        "{\n"
        "  (void) argc;\n"
        "  (void) argv;\n"
        "\n"
        f'  printf("hello world {spec.name} package\\n");\n'
        "  return 0;\n"
        "}\n"
    )
