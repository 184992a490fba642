#!/usr/bin/env bash
# Makes a station's DDS Security files: a certificate authority (identity and
# permissions CA in one), an identity per participant, the domain governance
# and each identity's permissions, both signed by the CA (S/MIME). Both
# vendors read the same files (`--security DIR` on every program, or
# FAHR_DDS_SECURITY=DIR).
#
#   make_station_security.sh OUT_DIR [--protection sign|encrypt] [--days N]
#                            [--ca-from DIR]
#
# --protection sign (default): discovery, liveliness and every topic's data
#   and submessages carry a message authentication code (GMAC); nothing is
#   encrypted. encrypt: the same, encrypted (AES-GCM).
# --ca-from DIR: reuse DIR's CA and identities and write only the governance
#   and permissions (a second protection level for the same station).
#
# OUT_DIR/
#   ca.cert.pem, ca.key.pem          the station's CA (keep ca.key.pem off the station)
#   governance.xml, governance.p7s   the domain's rules, signed
#   identities/NAME/cert.pem key.pem permissions.xml permissions.p7s
#
# NAME is the participant name a program joins with; its permissions:
#   haptic          publishes ForceCommand, ContactSet, SceneDescription
#   fem             publishes DeformationState
#   device_gateway  publishes DevicePose
#   replay          publishes DevicePose, ContactSet, DeformationState,
#                   SceneDescription (a recorded run, or the gateway's poses in
#                   a lockstep replay); never ForceCommand
#   visualizer      publishes fahr/RemoteInput (the mouse as the device) and
#                   fahr/GlotticView (the glottic view score)
#   lockstep_clock  publishes SimClock
#   logger, fahr_run_summary, fahr_dds_check, fault_probe: publish nothing
#   intruder        a valid identity allowed only ServiceStatus (tests: a
#                   participant the station knows, without the right to command)
#   fahr_transport_latency  publishes the bench's fahr/bench/ping and pong
# Every identity subscribes to every fahr topic; every one but the
# subscribe-only ones publishes its ServiceStatus, ServiceEvents and StepAck.
# Domains 0-230. Validity: --days (default 3650) from today.
set -euo pipefail
out=${1:?usage: make_station_security.sh OUT_DIR [--protection sign|encrypt] [--days N] [--ca-from DIR]}
shift
protection=sign
days=3650
ca_from=""
while [ $# -gt 0 ]; do
  case "$1" in
    --protection) protection=$2; shift 2 ;;
    --days) days=$2; shift 2 ;;
    --ca-from) ca_from=$2; shift 2 ;;
    *) echo "make_station_security: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
case "$protection" in
  sign) kind=SIGN ;;
  encrypt) kind=ENCRYPT ;;
  *) echo "make_station_security: --protection must be sign or encrypt" >&2; exit 2 ;;
esac
command -v openssl >/dev/null || { echo "make_station_security: openssl is needed" >&2; exit 1; }
mkdir -p "$out/identities"
out=$(cd "$out" && pwd)
organisation="fahr station"

# The CA: one key pair (ECDSA P-256) signs identities, governance and permissions.
if [ -n "$ca_from" ]; then
  ca_from=$(cd "$ca_from" && pwd)
  cp "$ca_from/ca.cert.pem" "$ca_from/ca.key.pem" "$out/"
else
  openssl ecparam -name prime256v1 -genkey -noout -out "$out/ca.key.pem"
  openssl req -new -x509 -key "$out/ca.key.pem" -out "$out/ca.cert.pem" -days "$days" \
    -subj "/O=$organisation/CN=fahr station CA" \
    -addext "basicConstraints=critical,CA:TRUE" -addext "keyUsage=critical,digitalSignature,keyCertSign,cRLSign"
fi

sign() {  # sign IN.xml OUT.p7s: S/MIME, clear text, signed by the CA
  openssl smime -sign -in "$1" -text -out "$2" -signer "$out/ca.cert.pem" -inkey "$out/ca.key.pem"
}

topics=(DevicePose ForceCommand ContactSet DeformationState SceneDescription ServiceStatus
  ServiceEvents SimClock StepAck GlotticView RemoteInput bench/ping bench/pong)
reports=(ServiceStatus ServiceEvents StepAck)

# Governance: who may join (only authenticated, permitted participants), and
# how each topic is protected. Every topic is under read and write access
# control.
{
  cat <<EOF
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id_range><min>0</min><max>230</max></id_range></domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>$kind</discovery_protection_kind>
      <liveliness_protection_kind>$kind</liveliness_protection_kind>
      <rtps_protection_kind>NONE</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>$kind</metadata_protection_kind>
          <data_protection_kind>$kind</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
EOF
} >"$out/governance.xml"
sign "$out/governance.xml" "$out/governance.p7s"

topic_list() {  # topic_list NAME...: <topic> elements
  for t in "$@"; do printf '            <topic>fahr/%s</topic>\n' "$t"; done
}

# One identity: key, certificate signed by the CA, permissions signed by the CA.
identity() {  # identity NAME PUBLISHED-TOPIC...
  local name=$1
  shift
  local dir="$out/identities/$name"
  mkdir -p "$dir"
  if [ -n "$ca_from" ]; then
    cp "$ca_from/identities/$name/cert.pem" "$ca_from/identities/$name/key.pem" "$dir/"
  else
    openssl ecparam -name prime256v1 -genkey -noout -out "$dir/key.raw.pem"
    openssl pkcs8 -topk8 -nocrypt -in "$dir/key.raw.pem" -out "$dir/key.pem"
    rm -f "$dir/key.raw.pem"
    openssl req -new -key "$dir/key.pem" -out "$dir/cert.csr" -subj "/O=$organisation/CN=$name"
    openssl x509 -req -in "$dir/cert.csr" -CA "$out/ca.cert.pem" -CAkey "$out/ca.key.pem" \
      -CAcreateserial -out "$dir/cert.pem" -days "$days" 2>/dev/null
    rm -f "$dir/cert.csr"
  fi
  local not_before not_after
  not_before=$(date -u +%Y-%m-%dT00:00:00)
  not_after=$(date -u -d "+$days days" +%Y-%m-%dT00:00:00)
  {
    cat <<EOF
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name="fahr_$name">
      <subject_name>CN=$name,O=$organisation</subject_name>
      <validity><not_before>$not_before</not_before><not_after>$not_after</not_after></validity>
      <allow_rule>
        <domains><id_range><min>0</min><max>230</max></id_range></domains>
EOF
    if [ $# -gt 0 ]; then
      echo "        <publish>"
      echo "          <topics>"
      topic_list "$@"
      echo "          </topics>"
      echo "          <partitions><partition>*</partition></partitions>"
      echo "        </publish>"
    fi
    echo "        <subscribe>"
    echo "          <topics>"
    topic_list "${topics[@]}"
    echo "          </topics>"
    echo "          <partitions><partition>*</partition></partitions>"
    echo "        </subscribe>"
    cat <<EOF
      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
EOF
  } >"$dir/permissions.xml"
  sign "$dir/permissions.xml" "$dir/permissions.p7s"
}

identity haptic ForceCommand ContactSet SceneDescription "${reports[@]}"
identity fem DeformationState "${reports[@]}"
identity device_gateway DevicePose "${reports[@]}"
identity replay DevicePose ContactSet DeformationState SceneDescription "${reports[@]}"
identity visualizer RemoteInput GlotticView "${reports[@]}"
identity lockstep_clock SimClock "${reports[@]}"
identity logger
identity fahr_run_summary
identity fahr_dds_check
identity fault_probe
identity intruder ServiceStatus
identity fahr_transport_latency bench/ping bench/pong
rm -f "$out/ca.cert.srl"
chmod 600 "$out/ca.key.pem" "$out"/identities/*/key.pem
echo "make_station_security: $protection station files in $out ($(ls "$out/identities" | wc -l) identities)"
