"""ROS substitutions (upstream's ``launch_ros.substitutions``): package folders and executables."""

from __future__ import annotations

import os
import shutil
from typing import Any

from ament_index_python.packages import get_package_prefix, get_package_share_directory
from launch.substitution import Substitution
from launch.substitutions import SubstitutionFailure
from launch.utilities import normalize_to_list_of_substitutions, perform_substitutions

__all__ = ["ExecutableInPackage", "FindPackage", "FindPackagePrefix", "FindPackageShare"]


class FindPackage(Substitution):
    def __init__(self, package: Any) -> None:
        self._package = normalize_to_list_of_substitutions(package)

    @property
    def package(self) -> list[Substitution]:
        return self._package

    def describe(self) -> str:
        return f"{type(self).__name__}(pkg={' + '.join(s.describe() for s in self.package)})"

    def find(self, package_name: str) -> str:
        raise NotImplementedError

    def perform(self, context: Any) -> str:
        # Raises ament_index_python's PackageNotFoundError, as upstream does.
        return self.find(perform_substitutions(context, self.package))

    def find_file(self, *parts: Any) -> Any:
        from launch.substitutions import PathJoinSubstitution

        return PathJoinSubstitution([self, *parts])

    def __truediv__(self, other: Any) -> Any:
        from launch.substitutions import PathJoinSubstitution

        return PathJoinSubstitution([self, other])


class FindPackagePrefix(FindPackage):
    def find(self, package_name: str) -> str:
        return str(get_package_prefix(package_name))


class FindPackageShare(FindPackage):
    def find(self, package_name: str) -> str:
        return str(get_package_share_directory(package_name))


class ExecutableInPackage(FindPackagePrefix):
    """``<prefix>/lib/<package>/<executable>``, as ``ros2 run`` finds it."""

    def __init__(self, executable: Any, package: Any) -> None:
        super().__init__(package)
        self.__executable = normalize_to_list_of_substitutions(executable)

    @property
    def executable(self) -> list[Substitution]:
        return self.__executable

    def perform(self, context: Any) -> str:
        executable = perform_substitutions(context, self.executable)
        package = perform_substitutions(context, self.package)
        prefix = super().perform(context)
        libexec = os.path.join(prefix, "lib", package)
        if not os.path.exists(libexec):
            raise SubstitutionFailure(
                f"package '{package}' found at '{prefix}', but libexec directory "
                f"'{libexec}' does not exist"
            )
        found = shutil.which(executable, path=libexec)
        if found is None:
            raise SubstitutionFailure(
                f"executable '{executable}' not found on the libexec directory '{libexec}' "
            )
        return found
