#!/usr/bin/env bash
# Builds the binaries for a GPU machine that cannot build (no packages there) into
# .gpu/bin, a folder git ignores, with a build-info.json that names the commit.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
export WAVETRACE_BUILD=${WAVETRACE_BUILD:-$root/build}
bash "$root/scripts/build.sh"
mkdir -p "$root/.gpu/bin"
cp "$WAVETRACE_BUILD/wavetrace" "$WAVETRACE_BUILD"/*_tests "$root/.gpu/bin/"
commit=$(git -C "$root" rev-parse HEAD)
dirty=$(git -C "$root" status --porcelain --untracked-files=no | grep -q . && echo true || echo false)
printf '{"commit": "%s", "dirty": %s}\n' "$commit" "$dirty" >"$root/.gpu/bin/build-info.json"
grep -qx '/.gpu/' "$root/.git/info/exclude" 2>/dev/null || echo '/.gpu/' >>"$root/.git/info/exclude"
