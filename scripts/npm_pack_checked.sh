# Sourced by the scripts that fetch npm packages (fetch_viewer_modules.sh,
# fetch_gltf_validator.sh); defines one function:
#
#   npm_pack_checked NAME SPEC INTEGRITY WORKDIR
#
# runs `npm pack SPEC` in WORKDIR, checks the tarball's sha512 against INTEGRITY (the
# registry's dist.integrity, pinned by the caller) and prints the tarball's file name. On a
# failure it says why, prefixed by NAME, on standard error and exits 1.
npm_pack_checked() {
  local name="$1" spec="$2" integrity="$3" work="$4" tgz got
  echo "$name: npm pack $spec" >&2
  tgz="$(cd "$work" && npm pack --silent "$spec" 2>"$work/npm.log" | tail -n 1)" || true
  if [ -z "$tgz" ] || [ ! -f "$work/$tgz" ]; then
    cat "$work/npm.log" >&2
    echo "$name: npm pack $spec failed (is the npm registry reachable?)" >&2
    exit 1
  fi
  got="sha512-$(openssl dgst -sha512 -binary "$work/$tgz" | base64 -w0)"
  if [ "$got" != "$integrity" ]; then
    echo "$name: $spec has integrity $got, expected $integrity: the registry" \
         "served something else; stop and find out why" >&2
    exit 1
  fi
  printf '%s\n' "$tgz"
}
