#!/usr/bin/env bash
# ssrlab's two commands. Each sets up what is missing (Debian packages, as root or through
# sudo; the Python package and its dependencies) and is safe to run again.
#
#   ./run.sh render [ssrlab render options]   render the default scene into renders/
#   ./run.sh test   [pytest options]          run the test suite
#
# PYTHON selects the interpreter (default: python3). Where that interpreter's environment is
# externally managed (PEP 668), the package goes into ./.venv instead.
set -euo pipefail
cd "$(dirname "$0")"

APT_PACKAGES=(
  build-essential pkg-config git
  libegl-dev libopengl-dev libegl1 libopengl0 libegl-mesa0 libgl1-mesa-dri   # EGL + GL (glvnd), llvmpipe
  libglm-dev libtinygltf-dev nlohmann-json3-dev libopenimageio-dev           # GLM, tinygltf, OpenImageIO
  libembree-dev                                                              # Embree: reference BVH
)
# What the tests need beyond the package: a real browser for the live viewer's page (tests/test_viewer.py)
TEST_APT_PACKAGES=(chromium)
PYTHON=${PYTHON:-python3}

log() { printf '\033[1m[run.sh]\033[0m %s\n' "$*" >&2; }

ensure_apt() {
  local missing=() p
  for p in "${APT_PACKAGES[@]}" "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  local sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { log "missing Debian packages (run as root): ${missing[*]}"; exit 1; }
    sudo="sudo"
  fi
  log "installing Debian packages: ${missing[*]}"
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

ensure_python_env() {
  command -v "$PYTHON" >/dev/null || { log "no $PYTHON on PATH (set PYTHON=...)"; exit 1; }
  if "$PYTHON" - <<'PY'
import sys, sysconfig, pathlib
sys.exit(0 if (pathlib.Path(sysconfig.get_paths()["stdlib"]) / "EXTERNALLY-MANAGED").exists()
         and sys.prefix == sys.base_prefix else 1)
PY
  then
    [ -x .venv/bin/python ] || { log "externally managed Python: creating .venv"; "$PYTHON" -m venv .venv; }
    PYTHON=.venv/bin/python
  fi
}

# Installs the package (with extras $1) unless the installed copy was built from these
# sources with those extras (the stamp records the source digest and the extras installed).
ensure_package() {
  local extras=$1 stamp=build/.install-stamp digest
  digest=$( { "$PYTHON" -c 'import sys; print(sys.executable, sys.version)';
              find CMakeLists.txt pyproject.toml cpp shaders python -type f ! -name '*.pyc' -print0 | sort -z |
              xargs -0 sha256sum; } | sha256sum | cut -d' ' -f1)
  if [ -f "$stamp" ] && [ "$(head -n1 "$stamp")" = "$digest" ] && { [ -z "$extras" ] || grep -qx "$extras" "$stamp"; } &&
     "$PYTHON" -c "import ssrlab._core" 2>/dev/null; then
    return 0
  fi
  log "building and installing ssrlab${extras:+[$extras]} with $PYTHON (the first build takes a few minutes)"
  "$PYTHON" -m pip install --disable-pip-version-check --root-user-action=ignore -q ".${extras:+[$extras]}"
  mkdir -p build && printf '%s\n%s\n' "$digest" "$extras" > "$stamp"
}

command=${1:-}
[ $# -gt 0 ] && shift
case "$command" in
  render)
    ensure_apt; ensure_python_env; ensure_package ""
    exec "$PYTHON" -m ssrlab render --scene spheres_and_boxes --layers 4 --set rays_per_pixel=4 --out renders/spheres_and_boxes "$@"
    ;;
  test)
    ensure_apt "${TEST_APT_PACKAGES[@]}"; ensure_python_env; ensure_package "test"
    exec "$PYTHON" -m pytest -q "$@"
    ;;
  *)
    sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
    ;;
esac
