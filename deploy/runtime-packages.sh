#!/usr/bin/env bash
# Prints the Debian packages that hold the shared libraries the given programs load (one a line,
# sorted): what a runtime image must install to run what was built here.
set -euo pipefail
(($# > 0)) || { echo "usage: runtime-packages.sh PROGRAM..." >&2; exit 2; }
libraries=$(ldd "$@" | awk '$2 == "=>" && $3 ~ /^\// { print $3 }' | sort -u)
for library in $libraries; do
  # Debian 12 merged /lib into /usr/lib, but dpkg records each file under the name it was packaged
  # with: try the path as found, as resolved, and the other of /lib and /usr/lib.
  resolved=$(readlink -f "$library")
  owner=""
  for candidate in "$library" "$resolved" "${resolved#/usr}" "/usr$library"; do
    owner=$(dpkg-query -S "$candidate" 2>/dev/null | head -1 | cut -d: -f1) && [[ -n "$owner" ]] && break
  done
  [[ -n "$owner" ]] || { echo "runtime-packages.sh: no package holds $library" >&2; exit 1; }
  echo "$owner"
done | sort -u
