#include "pki.hpp"

#include <openssl/bio.h>
#include <openssl/bn.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/rand.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>

#include <stdexcept>

namespace tomomap::fleet {

void KeyFree::operator()(EVP_PKEY* k) const { EVP_PKEY_free(k); }
void CertFree::operator()(X509* c) const { X509_free(c); }

namespace {

[[noreturn]] void fail(const std::string& what) {
  const unsigned long e = ERR_get_error();
  char reason[256] = "no detail";
  if (e) ERR_error_string_n(e, reason, sizeof reason);
  ERR_clear_error();
  throw std::runtime_error(what + " (" + reason + ")");
}

template <typename T>
T* check(T* p, const std::string& what) {
  if (!p) fail(what);
  return p;
}

void check(int ok, const std::string& what) {
  if (ok != 1) fail(what);
}

struct BioFree {
  void operator()(BIO* b) const { BIO_free_all(b); }
};
using Bio = std::unique_ptr<BIO, BioFree>;

Bio memory() { return Bio(check(BIO_new(BIO_s_mem()), "cannot allocate a buffer")); }
/// A read-only buffer over `text`, which must outlive it.
Bio memory(const std::string& text) {
  return Bio(check(BIO_new_mem_buf(text.data(), static_cast<int>(text.size())), "cannot allocate a buffer"));
}

std::string drain(BIO* b) {
  char* data = nullptr;
  const long n = BIO_get_mem_data(b, &data);
  return std::string(data, static_cast<size_t>(n));
}

std::string readFile(const std::string& path) {
  Bio in(BIO_new_file(path.c_str(), "r"));
  if (!in) fail("cannot read " + path);
  Bio out = memory();
  char buffer[4096];
  int n;
  while ((n = BIO_read(in.get(), buffer, sizeof buffer)) > 0) BIO_write(out.get(), buffer, n);
  return drain(out.get());
}

void setName(X509_NAME* name, const std::string& common_name, const std::string& org) {
  // O first, CN last: RFC 2253 prints the last entry first ("CN=...,O=...").
  check(X509_NAME_add_entry_by_txt(name, "O", MBSTRING_UTF8, reinterpret_cast<const unsigned char*>(org.c_str()), -1,
                                   -1, 0),
        "bad organisation name");
  check(X509_NAME_add_entry_by_txt(name, "CN", MBSTRING_UTF8,
                                   reinterpret_cast<const unsigned char*>(common_name.c_str()), -1, -1, 0),
        "bad common name");
}

void addExtension(X509* cert, X509* issuer, int nid, const char* value) {
  X509V3_CTX ctx;
  X509V3_set_ctx_nodb(&ctx);
  X509V3_set_ctx(&ctx, issuer, cert, nullptr, nullptr, 0);
  X509_EXTENSION* ext = check(X509V3_EXT_conf_nid(nullptr, &ctx, nid, value), "bad certificate extension");
  const int ok = X509_add_ext(cert, ext, -1);
  X509_EXTENSION_free(ext);
  check(ok, "cannot add a certificate extension");
}

/// A certificate for `key` valid from an hour ago (clocks of robots differ) for `days`.
Cert newCert(const Key& key, const std::string& common_name, const std::string& org, int days) {
  Cert cert(check(X509_new(), "cannot allocate a certificate"));
  check(X509_set_version(cert.get(), 2), "cannot set the certificate version");
  unsigned char serial[16];
  check(RAND_bytes(serial, sizeof serial), "no random serial number");
  serial[0] &= 0x7f;  // positive
  BIGNUM* bn = check(BN_bin2bn(serial, sizeof serial, nullptr), "cannot make a serial number");
  const bool ok = BN_to_ASN1_INTEGER(bn, X509_get_serialNumber(cert.get())) != nullptr;
  BN_free(bn);
  if (!ok) fail("cannot set the serial number");
  X509_gmtime_adj(X509_getm_notBefore(cert.get()), -3600);
  X509_gmtime_adj(X509_getm_notAfter(cert.get()), static_cast<long>(days) * 86400);
  check(X509_set_pubkey(cert.get(), key.get()), "cannot set the public key");
  setName(X509_get_subject_name(cert.get()), common_name, org);
  return cert;
}

}  // namespace

Key newKey() { return Key(check(EVP_EC_gen("P-256"), "cannot generate a P-256 key")); }

Cert newCa(const Key& key, const std::string& common_name, const std::string& org, int days) {
  Cert cert = newCert(key, common_name, org, days);
  check(X509_set_issuer_name(cert.get(), X509_get_subject_name(cert.get())), "cannot set the issuer");
  addExtension(cert.get(), cert.get(), NID_basic_constraints, "critical,CA:TRUE");
  // digitalSignature too: the CA signs the governance and permissions documents.
  addExtension(cert.get(), cert.get(), NID_key_usage, "critical,keyCertSign,cRLSign,digitalSignature");
  addExtension(cert.get(), cert.get(), NID_subject_key_identifier, "hash");
  if (X509_sign(cert.get(), key.get(), EVP_sha256()) <= 0) fail("cannot sign the CA certificate");
  return cert;
}

Cert issue(const Key& key, const std::string& common_name, const std::string& org, const Cert& ca, const Key& ca_key,
           int days) {
  Cert cert = newCert(key, common_name, org, days);
  check(X509_set_issuer_name(cert.get(), X509_get_subject_name(ca.get())), "cannot set the issuer");
  addExtension(cert.get(), ca.get(), NID_basic_constraints, "critical,CA:FALSE");
  addExtension(cert.get(), ca.get(), NID_key_usage, "critical,digitalSignature,keyAgreement");
  addExtension(cert.get(), ca.get(), NID_authority_key_identifier, "keyid:always");
  if (X509_sign(cert.get(), ca_key.get(), EVP_sha256()) <= 0) fail("cannot sign the certificate of " + common_name);
  return cert;
}

std::string subject(const Cert& cert) {
  Bio out = memory();
  X509_NAME_print_ex(out.get(), X509_get_subject_name(cert.get()), 0, XN_FLAG_RFC2253 & ~ASN1_STRFLGS_ESC_MSB);
  return drain(out.get());
}

std::string serialHex(const Cert& cert) {
  BIGNUM* bn = check(ASN1_INTEGER_to_BN(X509_get0_serialNumber(cert.get()), nullptr), "bad serial number");
  char* hex = BN_bn2hex(bn);
  std::string s(hex ? hex : "");
  OPENSSL_free(hex);
  BN_free(bn);
  return s;
}

std::string pem(const Cert& cert) {
  Bio out = memory();
  check(PEM_write_bio_X509(out.get(), cert.get()), "cannot write a certificate");
  return drain(out.get());
}

std::string pem(const Key& key) {
  Bio out = memory();
  check(PEM_write_bio_PrivateKey(out.get(), key.get(), nullptr, nullptr, 0, nullptr, nullptr),
        "cannot write a private key");
  return drain(out.get());
}

Cert readCert(const std::string& path) {
  const std::string text = readFile(path);  // the buffer reads from it: keep it alive
  Bio in = memory(text);
  return Cert(check(PEM_read_bio_X509(in.get(), nullptr, nullptr, nullptr), path + ": not a PEM certificate"));
}

Key readKey(const std::string& path) {
  const std::string text = readFile(path);
  Bio in = memory(text);
  return Key(check(PEM_read_bio_PrivateKey(in.get(), nullptr, nullptr, nullptr), path + ": not a PEM private key"));
}

std::string smimeSign(const std::string& document, const Cert& ca, const Key& ca_key) {
  constexpr int kFlags = PKCS7_DETACHED | PKCS7_TEXT;
  Bio in = memory(document);
  PKCS7* p7 = check(PKCS7_sign(ca.get(), ca_key.get(), nullptr, in.get(), kFlags), "cannot sign the document");
  Bio again = memory(document);  // the signing consumed the first reader
  Bio out = memory();
  const int ok = SMIME_write_PKCS7(out.get(), p7, again.get(), kFlags);
  PKCS7_free(p7);
  check(ok, "cannot write the signed document");
  return drain(out.get());
}

std::string smimeVerify(const std::string& signed_document, const Cert& ca) {
  Bio in = memory(signed_document);
  BIO* content = nullptr;
  PKCS7* p7 = SMIME_read_PKCS7(in.get(), &content);
  if (!p7) fail("not an S/MIME signed document");
  Bio content_owner(content);
  X509_STORE* store = X509_STORE_new();
  X509_STORE_add_cert(store, ca.get());
  Bio out = memory();
  const int ok = PKCS7_verify(p7, nullptr, store, content, out.get(), PKCS7_TEXT);
  X509_STORE_free(store);
  PKCS7_free(p7);
  if (ok != 1) fail("the signature does not verify against the CA");
  return drain(out.get());
}

std::string crl(const std::vector<std::string>& revoked, const Cert& ca, const Key& ca_key, int days) {
  X509_CRL* list = check(X509_CRL_new(), "cannot allocate a revocation list");
  std::unique_ptr<X509_CRL, decltype(&X509_CRL_free)> owner(list, X509_CRL_free);
  check(X509_CRL_set_version(list, 1), "cannot set the CRL version");
  check(X509_CRL_set_issuer_name(list, X509_get_subject_name(ca.get())), "cannot set the CRL issuer");
  ASN1_TIME* now = X509_gmtime_adj(nullptr, 0);
  ASN1_TIME* next = X509_gmtime_adj(nullptr, static_cast<long>(days) * 86400);
  X509_CRL_set1_lastUpdate(list, now);
  X509_CRL_set1_nextUpdate(list, next);
  for (const auto& hex : revoked) {
    BIGNUM* bn = nullptr;
    if (!BN_hex2bn(&bn, hex.c_str())) fail("bad serial number '" + hex + "'");
    X509_REVOKED* r = X509_REVOKED_new();
    ASN1_INTEGER* serial = BN_to_ASN1_INTEGER(bn, nullptr);
    X509_REVOKED_set_serialNumber(r, serial);
    X509_REVOKED_set_revocationDate(r, now);
    ASN1_INTEGER_free(serial);
    BN_free(bn);
    check(X509_CRL_add0_revoked(list, r), "cannot add a revoked serial");
  }
  ASN1_TIME_free(now);
  ASN1_TIME_free(next);
  X509_CRL_sort(list);
  if (X509_CRL_sign(list, ca_key.get(), EVP_sha256()) <= 0) fail("cannot sign the revocation list");
  Bio out = memory();
  check(PEM_write_bio_X509_CRL(out.get(), list), "cannot write the revocation list");
  return drain(out.get());
}

bool verify(const Cert& cert, const Cert& ca, const std::string& crl_pem, std::string& why) {
  X509_STORE* store = X509_STORE_new();
  X509_STORE_add_cert(store, ca.get());
  if (!crl_pem.empty()) {
    Bio in = memory(crl_pem);
    X509_CRL* list = PEM_read_bio_X509_CRL(in.get(), nullptr, nullptr, nullptr);
    if (!list) {
      X509_STORE_free(store);
      why = "not a PEM revocation list";
      return false;
    }
    X509_STORE_add_crl(store, list);
    X509_CRL_free(list);
    X509_STORE_set_flags(store, X509_V_FLAG_CRL_CHECK);
  }
  X509_STORE_CTX* ctx = X509_STORE_CTX_new();
  X509_STORE_CTX_init(ctx, store, cert.get(), nullptr);
  const bool ok = X509_verify_cert(ctx) == 1;
  if (!ok) why = X509_verify_cert_error_string(X509_STORE_CTX_get_error(ctx));
  X509_STORE_CTX_free(ctx);
  X509_STORE_free(store);
  return ok;
}

}  // namespace tomomap::fleet
