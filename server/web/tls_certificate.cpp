#include "tls_certificate.h"

#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/rand.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <system_error>

namespace fluidcast::server {
namespace {

template <class T, void (*Free)(T*)>
struct Freer {
  void operator()(T* p) const { Free(p); }
};
using Key = std::unique_ptr<EVP_PKEY, Freer<EVP_PKEY, EVP_PKEY_free>>;
using Certificate = std::unique_ptr<X509, Freer<X509, X509_free>>;
using Extension = std::unique_ptr<X509_EXTENSION, Freer<X509_EXTENSION, X509_EXTENSION_free>>;

struct FileCloser {
  void operator()(std::FILE* file) const { std::fclose(file); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

File open(const std::filesystem::path& path, const char* mode) {
  File file(std::fopen(path.c_str(), mode));
  if (!file) {
    throw std::runtime_error("TLS: cannot " + std::string(mode[0] == 'r' ? "read " : "write ") +
                             path.string() + ": " + std::generic_category().message(errno));
  }
  return file;
}

// Whether the certificate in `path` covers every address (and has not expired).
bool covers(const std::filesystem::path& path, const std::vector<std::string>& addresses) {
  std::FILE* raw = std::fopen(path.c_str(), "r");
  if (!raw) return false;
  const File file(raw);
  const Certificate certificate(PEM_read_X509(file.get(), nullptr, nullptr, nullptr));
  if (!certificate) return false;
  if (X509_cmp_current_time(X509_get0_notAfter(certificate.get())) <= 0) return false;
  for (const std::string& address : addresses) {
    if (X509_check_ip_asc(certificate.get(), address.c_str(), 0) != 1) return false;
  }
  return true;
}

void make(const TlsFiles& files, const std::vector<std::string>& addresses) {
  const Key key(EVP_EC_gen("P-256"));
  const Certificate certificate(X509_new());
  if (!key || !certificate) throw std::runtime_error("TLS: OpenSSL could not make a key");
  X509_set_version(certificate.get(), 2);
  std::uint32_t serial = 0;
  RAND_bytes(reinterpret_cast<unsigned char*>(&serial), sizeof serial);
  ASN1_INTEGER_set(X509_get_serialNumber(certificate.get()), serial & 0x7fffffff);
  X509_gmtime_adj(X509_getm_notBefore(certificate.get()), -3600);
  X509_gmtime_adj(X509_getm_notAfter(certificate.get()), 365L * 24 * 3600);
  X509_set_pubkey(certificate.get(), key.get());
  X509_NAME* name = X509_get_subject_name(certificate.get());
  X509_NAME_add_entry_by_txt(name, "CN", MBSTRING_ASC,
                             reinterpret_cast<const unsigned char*>("fluidcast (self-signed)"), -1,
                             -1, 0);
  X509_set_issuer_name(certificate.get(), name);
  std::string names = "DNS:localhost,IP:127.0.0.1";
  for (const std::string& address : addresses) {
    if (address != "127.0.0.1") names += ",IP:" + address;
  }
  X509V3_CTX context;
  X509V3_set_ctx_nodb(&context);
  X509V3_set_ctx(&context, certificate.get(), certificate.get(), nullptr, nullptr, 0);
  const Extension alternative(
      X509V3_EXT_conf_nid(nullptr, &context, NID_subject_alt_name, names.c_str()));
  if (!alternative || !X509_add_ext(certificate.get(), alternative.get(), -1) ||
      !X509_sign(certificate.get(), key.get(), EVP_sha256())) {
    throw std::runtime_error("TLS: OpenSSL could not sign a certificate for " + names);
  }
  // Key and certificate in one file, written aside and renamed into place: a second server
  // starting at the same moment reads either the old pair or the new one, never half of each.
  const std::filesystem::path aside =
      files.certificate.string() + ".new" + std::to_string(getpid());
  {
    const File out = open(aside, "w");
    chmod(aside.c_str(), 0600);
    if (!PEM_write_PrivateKey(out.get(), key.get(), nullptr, nullptr, 0, nullptr, nullptr) ||
        !PEM_write_X509(out.get(), certificate.get()) || std::fflush(out.get()) != 0) {
      throw std::runtime_error("TLS: cannot write " + aside.string());
    }
  }
  std::filesystem::rename(aside, files.certificate);
}

// Holds an exclusive lock on a file of the state folder while it lives: servers that start
// together (one per GPU, sharing the folder) make one certificate, not one each, of which the
// last renamed into place would leave the others serving theirs until they restart.
class FolderLock {
 public:
  explicit FolderLock(const std::filesystem::path& file)
      : fd_(::open(file.c_str(), O_RDONLY | O_CREAT | O_CLOEXEC, 0600)) {
    int locked = -1;
    while (fd_ >= 0 && (locked = flock(fd_, LOCK_EX)) != 0 && errno == EINTR) {
    }
    if (locked != 0) {
      const std::error_code error(errno, std::generic_category());
      if (fd_ >= 0) ::close(fd_);
      throw std::runtime_error("TLS: cannot lock " + file.string() + ": " + error.message());
    }
  }
  ~FolderLock() { ::close(fd_); }  // which lets the lock go
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  int fd_;
};

}  // namespace

TlsFiles self_signed_certificate(const std::filesystem::path& folder,
                                 const std::vector<std::string>& addresses) {
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error) {
    throw std::runtime_error("TLS: cannot make the state folder " + folder.string() + ": " +
                             error.message() + " (--state-dir)");
  }
  const std::filesystem::path both = folder / "self-signed.pem";  // the key, then the certificate
  const TlsFiles files{both, both};
  // Checked again under the lock: another server may have made it meanwhile. A certificate that
  // covers the addresses needs no lock (nor a folder that can be written).
  if (!covers(files.certificate, addresses)) {
    const FolderLock lock(folder / "self-signed.lock");
    if (!covers(files.certificate, addresses)) make(files, addresses);
  }
  return files;
}

std::filesystem::path default_state_folder() {
  if (const char* systemd = std::getenv("STATE_DIRECTORY"); systemd && *systemd) return systemd;
  if (const char* xdg = std::getenv("XDG_STATE_HOME"); xdg && *xdg) {
    return std::filesystem::path(xdg) / "fluidcast";
  }
  const char* home = std::getenv("HOME");
  return std::filesystem::path(home && *home ? home : ".") / ".local/state/fluidcast";
}

}  // namespace fluidcast::server
