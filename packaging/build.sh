#!/usr/bin/env bash
# Builds the one-folder FHA Studio bundle (packaging/dist/fha-studio/) with PyInstaller and starts
# it once: the CLI, then the GUI on the embedded simulated drive (headless, closes itself).
# Not part of CI's time budget. PYTHON may name an interpreter with PyInstaller and FHA Studio's
# dependencies (default: .venv/bin/python, else python3).
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/.." && pwd)"
PYTHON="${PYTHON:-}"
if [ -z "$PYTHON" ]; then
    if [ -x "$ROOT/.venv/bin/python" ]; then PYTHON="$ROOT/.venv/bin/python"; else PYTHON=python3; fi
fi
"$PYTHON" -m PyInstaller --version >/dev/null 2>&1 || {
    echo "PyInstaller is missing: $PYTHON -m pip install pyinstaller" >&2; exit 1; }
cd "$ROOT"
echo "== building with $("$PYTHON" -m PyInstaller --version) (one folder)"
"$PYTHON" -m PyInstaller --noconfirm --clean --log-level WARN \
    --distpath "$HERE/dist" --workpath "$HERE/build" "$HERE/fha-studio.spec"
APP="$HERE/dist/fha-studio"
cp "$HERE/fha-studio.desktop" "$APP/"
cp "$ROOT/resources/icons/fha-studio.png" "$APP/"
echo "== bundle: $APP ($(du -sh "$APP" | cut -f1))"
echo "== starting it once: the CLI"
# to a file, not a pipe into head: with pipefail, a closed pipe (exit 141) would end the script
"$APP/fha-studio" catalog FHA-25C-50-US250 > "$HERE/build/catalog.txt"
head -3 "$HERE/build/catalog.txt"
echo "== starting it once: the GUI on the embedded simulated drive (closes after 4 s)"
export QT_QPA_PLATFORM="${QT_QPA_PLATFORM:-offscreen}"
start=$(date +%s.%N)
"$APP/fha-studio" gui --quit-after-ms 4000
echo "== the GUI started, connected and closed cleanly ($(echo "$(date +%s.%N) - $start" | bc) s including the 4 s)"
echo "   install the desktop entry: cp $APP/fha-studio.desktop ~/.local/share/applications/ (Exec: put $APP on PATH)"
