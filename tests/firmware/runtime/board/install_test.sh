#!/bin/sh
# deployment_install_test: `cmake --install` of this build tree into a fresh
# temporary prefix, then checks what landed there and, if systemd-analyze is
# available, verifies the installed units.
#   install_test.sh CMAKE_COMMAND BINARY_DIR SOURCE_DIR
set -eu
cmake_command=$1
binary_dir=$2
source_dir=$3

tmp=$(mktemp -d "${TMPDIR:-/tmp}/rover_install_test_XXXXXX")
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix
failures=0
fail() {
  echo "FAIL: $*" >&2
  failures=$((failures + 1))
}

"$cmake_command" --install "$binary_dir" --prefix "$prefix" >"$tmp/install.log" 2>&1 || {
  cat "$tmp/install.log" >&2
  echo "FAIL: cmake --install failed (are the installed targets built?)" >&2
  exit 1
}

# Executables: every program target of this build (written by
# cmake/RoverInstall.cmake), at least roverd-sim and the rover-log tool.
programs=$(cat "$binary_dir/rover_install_programs.txt" | tr ';' ' ')
for program in roverd-sim rover-log; do
  case " $programs " in
    *" $program "*) ;;
    *) fail "$program is not among the installed programs ($programs)" ;;
  esac
done
for program in $programs; do
  [ -x "$prefix/bin/$program" ] || fail "bin/$program missing or not executable"
done

# Units, sysusers, configuration (identical to the sources).
for unit in rover-roudi.service rover-roverd.service rover-mapd.service; do
  cmp -s "$source_dir/firmware/systemd/$unit" "$prefix/lib/systemd/system/$unit" ||
    fail "lib/systemd/system/$unit missing or different"
done
cmp -s "$source_dir/firmware/systemd/rover.sysusers.conf" "$prefix/lib/sysusers.d/rover.conf" ||
  fail "lib/sysusers.d/rover.conf missing or different"
for config in board.yaml roudi.toml; do
  cmp -s "$source_dir/firmware/config/$config" "$prefix/etc/rover/$config" ||
    fail "etc/rover/$config missing or different"
done

# Re-installing over an edited board.yaml keeps the edit and adds board.yaml.dist.
echo "# edited on the board" >>"$prefix/etc/rover/board.yaml"
cp "$prefix/etc/rover/board.yaml" "$tmp/edited.yaml"
"$cmake_command" --install "$binary_dir" --prefix "$prefix" >"$tmp/install2.log" 2>&1 || {
  cat "$tmp/install2.log" >&2
  fail "second cmake --install failed"
}
cmp -s "$tmp/edited.yaml" "$prefix/etc/rover/board.yaml" || fail "re-install overwrote the edited board.yaml"
cmp -s "$source_dir/firmware/config/board.yaml" "$prefix/etc/rover/board.yaml.dist" ||
  fail "re-install did not write board.yaml.dist"

# A board install: prefix /usr puts the configuration in /etc (staged with
# DESTDIR, so nothing outside the temporary folder is touched).
DESTDIR=$tmp/stage "$cmake_command" --install "$binary_dir" --prefix /usr >"$tmp/install3.log" 2>&1 || {
  cat "$tmp/install3.log" >&2
  fail "cmake --install --prefix /usr with DESTDIR failed"
}
[ -f "$tmp/stage/etc/rover/board.yaml" ] || fail "prefix /usr: no /etc/rover/board.yaml"
[ -f "$tmp/stage/usr/lib/systemd/system/rover-roverd.service" ] ||
  fail "prefix /usr: no /usr/lib/systemd/system/rover-roverd.service"
[ -x "$tmp/stage/usr/bin/roverd-sim" ] || fail "prefix /usr: no /usr/bin/roverd-sim"

# systemd-analyze verify on copies of the installed units whose ExecStart
# points into the prefix (the units name /usr/bin/..., which is not where
# this test installed them). A program this build has no target for (roverd
# or mapd not written yet) stands in as /bin/true: the check is about the
# unit files. Any warning about a rover unit fails the test; unrelated
# warnings of the host's own units are printed only.
if command -v systemd-analyze >/dev/null 2>&1; then
  units=$tmp/units
  mkdir -p "$units"
  for unit in rover-roudi.service rover-roverd.service rover-mapd.service; do
    sed_script=""
    for binary in $(sed -n 's|^ExecStart=/usr/bin/\([^ ]*\).*|\1|p' "$prefix/lib/systemd/system/$unit"); do
      if [ -x "$prefix/bin/$binary" ]; then
        sed_script="$sed_script;s|^ExecStart=/usr/bin/$binary|ExecStart=$prefix/bin/$binary|"
      elif [ ! -x "/usr/bin/$binary" ]; then
        sed_script="$sed_script;s|^ExecStart=/usr/bin/$binary|ExecStart=/bin/true|"
      fi
    done
    sed "${sed_script#;}" "$prefix/lib/systemd/system/$unit" >"$units/$unit"
  done
  verify_rc=0
  (cd "$units" && systemd-analyze verify --man=no ./rover-roudi.service \
    ./rover-roverd.service ./rover-mapd.service) >"$tmp/verify.log" 2>&1 || verify_rc=$?
  if grep -q 'rover-' "$tmp/verify.log"; then
    cat "$tmp/verify.log" >&2
    fail "systemd-analyze verify reported a problem with a rover unit"
  elif [ "$verify_rc" -ne 0 ]; then
    # Nothing about our units: the tool itself cannot run here (a sandbox).
    cat "$tmp/verify.log"
    echo "systemd-analyze verify could not run (status $verify_rc): units not verified"
  elif [ -s "$tmp/verify.log" ]; then
    echo "systemd-analyze verify (not about rover units, ignored):"
    cat "$tmp/verify.log"
  fi
else
  echo "systemd-analyze not found: units not verified"
fi

if [ "$failures" -ne 0 ]; then
  echo "$failures failure(s)" >&2
  exit 1
fi
echo "installed and verified in a temporary prefix"
