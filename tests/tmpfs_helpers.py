"""A small tmpfs for the fault tests (a full or read-only disk): mounted as root, else the test
is skipped."""

import os
import shutil
import subprocess

import pytest


def small_tmpfs(path, options):
    """A tmpfs mounted at ``path`` with mount ``options`` (e.g. ``"size=64k"``, ``"ro"``);
    root only, else the test is skipped. Unmount with :func:`unmount`."""
    if os.geteuid() != 0 or shutil.which("mount") is None:
        pytest.skip("needs root to mount a small tmpfs")
    path.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(path)],
                          capture_output=True)
    if done.returncode != 0:
        pytest.skip(f"tmpfs not available: {done.stderr.decode().strip()}")
    return path


def unmount(path):
    subprocess.run(["umount", str(path)], check=True)


def fill(path):
    """Write zeros to ``path`` until the disk is full."""
    handle = os.open(path, os.O_WRONLY | os.O_CREAT, 0o644)
    try:
        while True:
            os.write(handle, b"\0" * 4096)
    except OSError:
        pass
    finally:
        os.close(handle)
