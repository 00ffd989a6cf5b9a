# Shared by scripts/start and scripts/test: a Python >= 3.11 virtual environment in .venv
# with FHA Studio installed, and the Qt system libraries a bare Debian/Ubuntu lacks.
# Sourced, not run.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="${FHA_VENV:-$ROOT/.venv}"

find_python() {
    for candidate in "${PYTHON:-}" python3.13 python3.12 python3.11 python3; do
        [ -n "$candidate" ] || continue
        if command -v "$candidate" >/dev/null 2>&1 &&
            "$candidate" -c 'import sys; raise SystemExit(sys.version_info < (3, 11))' 2>/dev/null; then
            echo "$candidate"
            return 0
        fi
    done
    echo "FHA Studio needs Python >= 3.11 (with venv); none was found on PATH." >&2
    return 1
}

# Debian package names of the shared libraries Qt needs; see shared/reference/qt-stack-notes.md.
# sigrok-cli (a command) streams the bench instruments: logic analyzers, oscilloscopes, DAQs.
BENCH_PACKAGES="sigrok-cli"
# The tests start a throw-away PostgreSQL server of their own (the plant's register on a server;
# tests/support/postgres.py); scripts/start stays on the SQLite file and does not need it.
SERVER_PACKAGES="postgresql"
QT_OFFSCREEN_PACKAGES="libglib2.0-0 libegl1 libgl1 libdbus-1-3 libfontconfig1 libxkbcommon0"
QT_XCB_PACKAGES="libxcb-cursor0 libxcb-icccm4 libxcb-keysyms1 libxcb-shape0 libxcb-xkb1 libxkbcommon-x11-0"

missing_libraries() {
    # Prints the Debian packages whose library is not known to the dynamic linker (or whose
    # command is missing).
    local pkg lib
    for pkg in $1; do
        case "$pkg" in
            libglib2.0-0) lib=libglib-2.0.so.0 ;;
            libegl1) lib=libEGL.so.1 ;;
            libgl1) lib=libGL.so.1 ;;
            libdbus-1-3) lib=libdbus-1.so.3 ;;
            libfontconfig1) lib=libfontconfig.so.1 ;;
            libxkbcommon0) lib=libxkbcommon.so.0 ;;
            libxcb-cursor0) lib=libxcb-cursor.so.0 ;;
            libxcb-icccm4) lib=libxcb-icccm.so.4 ;;
            libxcb-keysyms1) lib=libxcb-keysyms.so.1 ;;
            libxcb-shape0) lib=libxcb-shape.so.0 ;;
            libxcb-xkb1) lib=libxcb-xkb.so.1 ;;
            libxkbcommon-x11-0) lib=libxkbcommon-x11.so.0 ;;
            poppler-utils)  # a command, not a library: pdftotext checks the report PDFs' text
                command -v pdftotext >/dev/null || echo -n "$pkg "
                continue ;;
            sigrok-cli)  # a command: the acquisition engine of the bench instruments
                command -v sigrok-cli >/dev/null || echo -n "$pkg "
                continue ;;
            postgresql)  # the server's programs, not on PATH (Debian keeps them per version)
                ls /usr/lib/postgresql/*/bin/initdb >/dev/null 2>&1 || echo -n "$pkg "
                continue ;;
            *) lib="$pkg" ;;
        esac
        if ! /sbin/ldconfig -p 2>/dev/null | grep -q "$lib"; then echo -n "$pkg "; fi
    done
}

ensure_system_packages() {
    local missing
    missing="$(missing_libraries "$1")"
    [ -z "$missing" ] && return 0
    echo "Installing the system packages this machine lacks: $missing" >&2
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
        (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $missing) >&2
    elif command -v sudo >/dev/null && sudo -n true 2>/dev/null && command -v apt-get >/dev/null; then
        (sudo apt-get update -qq && sudo DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $missing) >&2
    else
        echo "Cannot install them without root. Run this once, then try again:" >&2
        echo "    sudo apt-get install -y $missing" >&2
        return 1
    fi
}

ensure_venv() {
    # $1: the pip extra to install ("" or "test").
    local python spec
    python="$(find_python)"
    if [ ! -x "$VENV/bin/python" ]; then
        "$python" -m venv "$VENV" || {
            echo "Could not create a virtual environment; on Debian/Ubuntu: sudo apt-get install -y python3-venv" >&2
            return 1
        }
    fi
    spec="$ROOT"
    [ -n "$1" ] && spec="$ROOT[$1]"
    "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check --upgrade pip >&2
    "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check -e "$spec" >&2
}
