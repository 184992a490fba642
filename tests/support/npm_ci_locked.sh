# Sourced by test scripts: npm_ci_locked SRC_DIR DEST_DIR installs the npm
# packages SRC_DIR's package-lock.json pins into DEST_DIR (npm ci), again only
# when the lock changed since the last install.
npm_ci_locked() {
  local src=$1 dest=$2
  mkdir -p "$dest"
  cp "$src/package.json" "$src/package-lock.json" "$dest/"
  if ! cmp -s "$dest/package-lock.json" "$dest/node_modules/.fahr-lock" 2>/dev/null; then
    (cd "$dest" && npm ci --no-audit --no-fund --loglevel=error)
    cp "$dest/package-lock.json" "$dest/node_modules/.fahr-lock"
  fi
}
