"""Real data that ships in Debian packages, found on the system or fetched into a cache folder.

Like ``scripts/fetch_test_data.sh`` does for darknet's photos, nothing is installed on the
system: ``apt-get download`` fetches the package file and only the wanted part of its contents is
unpacked (``dpkg-deb --fsys-tarfile``, read as a tar stream) into a cache folder; none of the
package's dependencies come along. The part is unpacked beside its final place and then renamed
into it, so an interrupted fetch never leaves a half-unpacked folder that looks complete.

Where the data is looked for, in order: the system (the package installed with apt), then the
cache: ``$SAILOR_DATA_CACHE`` when set, else ``build/test-data`` of a source checkout (where the
fetch script puts darknet), else ``~/.cache/merlin2_sailor/debian``.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tarfile
import tempfile
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from merlin2_sailor.errors import DependencyError

CACHE_ENVIRONMENT_VARIABLE = "SAILOR_DATA_CACHE"
DOWNLOAD_TIMEOUT_SECONDS = 600.0


@dataclass(frozen=True, slots=True)
class DebianData:
    """A file or folder inside a Debian package.

    ``member``: its path inside the package, relative to the file-system root (as it would be
    installed, without the leading slash); ``purpose``: what needs it, for error messages.
    """

    package: str
    member: str
    purpose: str

    @property
    def installed_path(self) -> Path:
        return Path("/") / self.member


def default_cache_directory() -> Path:
    """Where fetched packages are unpacked (see the module docstring)."""
    configured = os.environ.get(CACHE_ENVIRONMENT_VARIABLE)
    if configured:
        return Path(configured).expanduser()
    source_root = Path(__file__).resolve().parent.parent.parent
    if (source_root / "scripts" / "fetch_test_data.sh").is_file():
        return source_root / "build" / "test-data"
    return Path.home() / ".cache" / "merlin2_sailor" / "debian"


def locate(data: DebianData, cache: Path | None = None, fetch: bool = True) -> Path:
    """Return the path of ``data``: installed, already in the cache, or fetched into it now.

    Raises :class:`DependencyError` saying what to install or run when it cannot be had.
    """
    if data.installed_path.exists():
        return data.installed_path
    cache = cache or default_cache_directory()
    cached = cache / data.member
    if cached.exists():
        return cached
    if not fetch:
        raise DependencyError(
            f"{data.purpose} needs Debian's {data.package} package: install it "
            f"(sudo apt-get install {data.package}) or let the replay fetch it into {cache}"
        )
    fetch_member(data, cache)
    return cached


def fetch_member(data: DebianData, cache: Path) -> None:
    """Download ``data.package`` and unpack ``data.member`` from it into ``cache``."""
    for tool in ("apt-get", "dpkg-deb"):
        if shutil.which(tool) is None:
            raise DependencyError(
                f"{data.purpose} needs Debian's {data.package} package, and {tool} is not available here "
                f"(not Debian or Ubuntu): copy {data.installed_path} from a Debian machine and pass its path "
                "with --data"
            )
    packages = cache / "packages"
    packages.mkdir(parents=True, exist_ok=True)
    archive = _download(data, packages)
    try:
        _unpack(archive, data, cache)
    finally:
        archive.unlink(missing_ok=True)  # the unpacked part is what is kept; the package is large


def _download(data: DebianData, folder: Path) -> Path:
    for package_file in folder.glob(f"{data.package}_*.deb"):
        package_file.unlink()  # a leftover of an interrupted fetch
    failure = _apt_get_download(data.package, folder)
    if failure and hasattr(os, "geteuid") and os.geteuid() == 0:
        # The package lists may be missing or stale on a new machine.
        subprocess.run(["apt-get", "update", "-qq"], capture_output=True, timeout=DOWNLOAD_TIMEOUT_SECONDS, check=False)
        failure = _apt_get_download(data.package, folder)
    archives = sorted(folder.glob(f"{data.package}_*.deb"))
    if failure or not archives:
        raise DependencyError(
            f"{data.purpose} needs Debian's {data.package} package, and `apt-get download {data.package}` failed"
            f" ({failure or 'no package file'}); run 'sudo apt-get update' and try again, install it with "
            f"'sudo apt-get install {data.package}', or pass the data's path with --data"
        )
    return archives[-1]


def _apt_get_download(package: str, folder: Path) -> str:
    """Run ``apt-get download``; return '' on success, else the reason in one line."""
    try:
        completed = subprocess.run(
            ["apt-get", "download", package], cwd=folder, capture_output=True, text=True,
            timeout=DOWNLOAD_TIMEOUT_SECONDS, check=False,
        )
    except (OSError, subprocess.TimeoutExpired) as error:
        return str(error)
    if completed.returncode == 0:
        return ""
    lines = [line.strip() for line in completed.stderr.splitlines() if line.strip()]
    errors = [line for line in lines if line.startswith("E:")]
    return (errors or lines or [f"exit status {completed.returncode}"])[-1]


def _unpack(archive: Path, data: DebianData, cache: Path) -> None:
    """Unpack the members under ``data.member`` into a scratch folder, then rename into place."""
    wanted = PurePosixPath(data.member)
    cache.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix=f".unpack-{data.package}-", dir=cache) as scratch:
        process = subprocess.Popen(["dpkg-deb", "--fsys-tarfile", str(archive)], stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE)
        assert process.stdout is not None
        found = 0
        try:
            with tarfile.open(fileobj=process.stdout, mode="r|") as stream:
                for member in stream:
                    name = PurePosixPath(member.name.removeprefix("./"))
                    if name == wanted or wanted in name.parents:
                        member.name = str(name)
                        stream.extract(member, scratch, filter="data")
                        found += 1
        except tarfile.TarError as error:
            raise DependencyError(f"could not unpack {archive.name}: {error}; delete it and try again") from error
        finally:
            process.stdout.close()
            stderr = process.stderr.read().decode(errors="replace") if process.stderr else ""
            if process.stderr:
                process.stderr.close()
            process.wait()
        if process.returncode != 0 or found == 0:
            reason = stderr.strip() or f"{data.member} is not in the package"
            raise DependencyError(f"could not unpack {data.member} from {archive.name}: {reason}")
        target = cache / data.member
        target.parent.mkdir(parents=True, exist_ok=True)
        try:
            os.replace(Path(scratch) / data.member, target)
        except OSError:
            if not target.exists():
                raise
            # Another replay fetching at the same time got there first; its copy is as good.
