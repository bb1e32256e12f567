"""A throw-away PostgreSQL 15 for the Python tests (the C++ tests use tests/fleet/pg_server.hpp):
initdb into a temporary directory, a Unix socket in it and no TCP, run as the `postgres` user
when the test runs as root (the server refuses root). `unavailable()` says why it cannot run."""
import os
import pwd
import shutil
import subprocess
import tempfile

PG_BIN = "/usr/lib/postgresql/15/bin"


def unavailable():
    if not os.path.exists(os.path.join(PG_BIN, "initdb")):
        return "PostgreSQL 15 server binaries not installed (Debian postgresql-15)"
    if os.geteuid() == 0:
        try:
            pwd.getpwnam("postgres")
        except KeyError:
            return "running as root and no 'postgres' user to run the server as"
    return None


class Postgres:
    def __init__(self):
        self.dir = tempfile.mkdtemp(prefix="station-pg-")
        self.as_user = []
        if os.geteuid() == 0:
            pw = pwd.getpwnam("postgres")
            os.chown(self.dir, pw.pw_uid, pw.pw_gid)
            self.as_user = ["runuser", "-u", "postgres", "--"]
        with open(os.devnull, "w") as null:
            subprocess.run(self.as_user + [PG_BIN + "/initdb", "-D", self.dir + "/data", "-A",
                                           "trust", "-U", "station", "-E", "UTF8", "--locale=C",
                                           "--no-sync"], check=True, stdout=null, stderr=null)
        self.start()

    def pg_ctl(self, *args):
        with open(os.devnull, "w") as null:
            subprocess.run(self.as_user + [PG_BIN + "/pg_ctl", "-D", self.dir + "/data"] +
                           list(args), check=True, stdout=null, stderr=null)

    def start(self):
        self.pg_ctl("-l", self.dir + "/server.log", "-w", "-t", "60", "-o",
                    "-c listen_addresses='' -c unix_socket_directories=%s -c fsync=off" % self.dir,
                    "start")

    def stop(self):
        self.pg_ctl("-m", "fast", "-w", "stop")

    def url(self, db="postgres"):
        return "postgresql:///%s?host=%s&user=station" % (db, self.dir)

    def query(self, sql, db="postgres"):
        out = subprocess.run([PG_BIN + "/psql", "-X", "-q", "-A", "-t", "-h", self.dir, "-U",
                              "station", "-d", db, "-c", sql], check=True, capture_output=True,
                             text=True).stdout
        return out.strip()

    def close(self):
        try:
            self.pg_ctl("-m", "immediate", "stop")
        except subprocess.CalledProcessError:
            pass
        shutil.rmtree(self.dir, ignore_errors=True)
