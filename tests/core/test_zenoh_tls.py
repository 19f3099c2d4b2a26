"""Zenoh over TLS with a certificate authority made in the test: a peer that trusts the CA
talks to the listening side; one that trusts another CA is refused with one clear error."""

from __future__ import annotations

import datetime
import ipaddress
import time
from pathlib import Path
from typing import Any

import pytest
from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import ec
from cryptography.x509.oid import NameOID

from roverlab.core import Context
from roverlab.core.transport.zenoh import TransportError, ZenohOptions, ZenohTransport
from roverlab.msgs import String
from tests.helpers.net import free_port, wait_until

pytestmark = pytest.mark.zenoh


def _name(common: str) -> x509.Name:
    return x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, common)])


def _pem_key(key: Any) -> bytes:
    return bytes(
        key.private_bytes(
            serialization.Encoding.PEM,
            serialization.PrivateFormat.PKCS8,
            serialization.NoEncryption(),
        )
    )


def _make_ca(directory: Path, common: str) -> tuple[Path, Any, x509.Certificate]:
    """A self-signed CA certificate (written to ``directory/common.pem``) and its key."""
    key = ec.generate_private_key(ec.SECP256R1())
    now = datetime.datetime.now(datetime.UTC)
    cert = (
        x509.CertificateBuilder()
        .subject_name(_name(common))
        .issuer_name(_name(common))
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(now - datetime.timedelta(minutes=5))
        .not_valid_after(now + datetime.timedelta(days=1))
        .add_extension(x509.BasicConstraints(ca=True, path_length=None), critical=True)
        .add_extension(
            x509.KeyUsage(
                digital_signature=True,
                content_commitment=False,
                key_encipherment=False,
                data_encipherment=False,
                key_agreement=False,
                key_cert_sign=True,
                crl_sign=True,
                encipher_only=False,
                decipher_only=False,
            ),
            critical=True,
        )
        .sign(key, hashes.SHA256())
    )
    path = directory / f"{common}.pem"
    path.write_bytes(cert.public_bytes(serialization.Encoding.PEM))
    return path, key, cert


def _make_server_cert(directory: Path, ca_key: Any, ca_cert: x509.Certificate) -> tuple[Path, Path]:
    """The robot's certificate for 127.0.0.1, signed by the CA: (cert file, key file)."""
    key = ec.generate_private_key(ec.SECP256R1())
    now = datetime.datetime.now(datetime.UTC)
    cert = (
        x509.CertificateBuilder()
        .subject_name(_name("robot"))
        .issuer_name(ca_cert.subject)
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(now - datetime.timedelta(minutes=5))
        .not_valid_after(now + datetime.timedelta(days=1))
        .add_extension(
            x509.SubjectAlternativeName(
                [x509.IPAddress(ipaddress.ip_address("127.0.0.1")), x509.DNSName("localhost")]
            ),
            critical=False,
        )
        .sign(ca_key, hashes.SHA256())
    )
    cert_path, key_path = directory / "robot.pem", directory / "robot.key"
    cert_path.write_bytes(cert.public_bytes(serialization.Encoding.PEM))
    key_path.write_bytes(_pem_key(key))
    return cert_path, key_path


def test_tls_with_a_self_signed_ca(tmp_path: Path) -> None:
    ca_path, ca_key, ca_cert = _make_ca(tmp_path, "lab-ca")
    other_ca, _, _ = _make_ca(tmp_path, "other-ca")
    cert, key = _make_server_cert(tmp_path, ca_key, ca_cert)
    ep = f"tls/127.0.0.1:{free_port()}"

    robot = Context(clock="wall")
    pub = robot.create_node("robot").create_publisher(String, "/chatter", 10)
    robot.add_transport(
        ZenohTransport(
            ZenohOptions(
                listen=(ep,), tls_root_ca=str(ca_path), tls_cert=str(cert), tls_key=str(key)
            )
        )
    )
    laptop = Context(clock="wall")
    got: list[str] = []
    laptop.create_node("op").create_subscription(
        String, "/chatter", lambda m: got.append(m.data), 10
    )
    laptop.add_transport(
        ZenohTransport(
            ZenohOptions(listen=(), connect=(ep,), tls_root_ca=str(ca_path), connect_timeout_s=5.0)
        )
    )
    for c in (robot, laptop):
        c.spin_in_thread()
    try:
        assert wait_until(lambda: pub.topic.remote_send is not None, timeout=10)
        deadline = time.monotonic() + 10
        while len(got) < 3 and time.monotonic() < deadline:
            pub.publish(String(data="over tls"))
            time.sleep(0.05)
        assert len(got) >= 3 and set(got) == {"over tls"}

        # a peer that trusts another CA does not accept the robot's certificate
        with pytest.raises(TransportError) as err:
            ZenohTransport(
                ZenohOptions(
                    listen=(), connect=(ep,), tls_root_ca=str(other_ca), connect_timeout_s=3.0
                )
            )
        assert str(err.value) == (
            f"{ep} refused the TLS session: its certificate is not signed by "
            f"--tls-root-ca {other_ca} or does not name that host"
        )
        # and one that trusts no CA at all is told to give one
        with pytest.raises(TransportError, match=r"no TLS session: give --tls-root-ca"):
            ZenohTransport(ZenohOptions(listen=(), connect=(ep,), connect_timeout_s=3.0))
    finally:
        for c in (robot, laptop):
            c.shutdown()
