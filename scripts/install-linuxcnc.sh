#!/usr/bin/env bash
# Installs LinuxCNC's standalone G-code interpreter `rs274` (Debian package linuxcnc-uspace), with
# which tests/post_6axis.rs checks every LinuxCNC program post-6axis writes (the test is skipped
# when rs274 is absent). Needs root and Debian's package registry; about 100 packages, 2-3 minutes.
# For CI, run it before `make test` (e.g. from .ci/run).
set -euo pipefail
if command -v rs274 >/dev/null 2>&1; then
  echo "rs274 already installed: $(command -v rs274)"
  exit 0
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -q
apt-get install -y -q --no-install-recommends linuxcnc-uspace
command -v rs274
