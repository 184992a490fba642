#!/usr/bin/env bash
# Runs a command inside a fresh network namespace that holds only loopback
# (with multicast on, so DDS discovery works), bounded in time, and removes
# the namespace afterwards. Multi-process DDS tests run through this so they
# never touch a real network. Needs root (CI runs as root); without it the
# test fails loudly rather than skipping.
set -euo pipefail
ns="fahr-test-$$-${RANDOM}"
if ! ip netns add "$ns" 2>/tmp/fahr-netns-err.$$; then
  echo "run_in_netns: cannot create network namespace '$ns': $(cat /tmp/fahr-netns-err.$$)" >&2
  echo "run_in_netns: multi-process tests need root or CAP_NET_ADMIN" >&2
  rm -f /tmp/fahr-netns-err.$$
  exit 1
fi
rm -f /tmp/fahr-netns-err.$$
trap 'ip netns del "$ns" 2>/dev/null || true' EXIT
ip -n "$ns" link set lo up
ip -n "$ns" link set lo multicast on
ip -n "$ns" route add 224.0.0.0/4 dev lo
timeout --kill-after=5 "${FAHR_NETNS_TIMEOUT:-900}" ip netns exec "$ns" "$@"
