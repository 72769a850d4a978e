#pragma once
// The few X.509 and S/MIME operations a fleet needs, on OpenSSL's libcrypto:
// P-256 keys, a self-signed CA, certificates it issues, a revocation list and
// S/MIME-signed documents as DDS Security reads them. Errors throw
// std::runtime_error with OpenSSL's reason.
#include <memory>
#include <string>
#include <vector>

typedef struct evp_pkey_st EVP_PKEY;
typedef struct x509_st X509;

namespace tomomap::fleet {

struct KeyFree {
  void operator()(EVP_PKEY* k) const;
};
struct CertFree {
  void operator()(X509* c) const;
};
using Key = std::unique_ptr<EVP_PKEY, KeyFree>;
using Cert = std::unique_ptr<X509, CertFree>;

/// A new ECDSA key on NIST P-256 (what DDS Security's PKI-DH signs with).
Key newKey();

/// A self-signed CA certificate valid for `days`, subject "CN=<common_name>,O=<org>".
Cert newCa(const Key& key, const std::string& common_name, const std::string& org, int days);

/// A certificate for `key` issued by the CA, subject "CN=<common_name>,O=<org>".
/// Serial numbers are random (128 bits), so a revocation names one certificate.
Cert issue(const Key& key, const std::string& common_name, const std::string& org, const Cert& ca, const Key& ca_key,
           int days);

/// Subject in RFC 2253 form ("CN=alpha,O=tomomap fleet"), as DDS permissions name it.
std::string subject(const Cert& cert);
/// Serial number in hexadecimal.
std::string serialHex(const Cert& cert);

std::string pem(const Cert& cert);
/// The private key, PKCS#8 PEM, unencrypted (a daemon starts unattended).
std::string pem(const Key& key);
Cert readCert(const std::string& path);
Key readKey(const std::string& path);

/// `document` signed by the CA as S/MIME (multipart/signed, detached, text):
/// the form Fast DDS verifies governance and permissions documents in.
std::string smimeSign(const std::string& document, const Cert& ca, const Key& ca_key);
/// The signed text if the signature verifies against `ca`; throws otherwise.
std::string smimeVerify(const std::string& signed_document, const Cert& ca);

/// A revocation list signed by the CA naming `revoked` (serials in hex),
/// valid for `days`.
std::string crl(const std::vector<std::string>& revoked, const Cert& ca, const Key& ca_key, int days);

/// Whether `cert` chains to `ca`, is within its validity and, if `crl_pem` is
/// not empty, not revoked by it; on false, `why` says why.
bool verify(const Cert& cert, const Cert& ca, const std::string& crl_pem, std::string& why);

}  // namespace tomomap::fleet
