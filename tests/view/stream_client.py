"""A client of `algray view`'s frame stream, for the tests: GET /stream on a socket of its own, the chunked body
read back as the server's messages ([u32 header bytes][u32 body bytes][header JSON][body], big-endian), and
states posted to /state."""
import json
import socket
import struct
import urllib.error
import urllib.parse
import urllib.request


class Stream:
    """One page's stream. `status` is the answer's status; a refusal's JSON is in `error`. `receive_buffer`: a
    small socket receive buffer, for a client that reads slowly or not at all."""

    def __init__(self, host, port, page, timeout=60, receive_buffer=None):
        self.sock = socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET, socket.SOCK_STREAM)
        if receive_buffer:
            self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, receive_buffer)
        self.sock.settimeout(timeout)
        self.sock.connect((host, port))
        self.sock.sendall(f"GET /stream?page={page} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n".encode())
        self.buf = b""
        self.body = b""
        head = self._until(b"\r\n\r\n").decode("latin-1").split("\r\n")
        self.status = int(head[0].split()[1])
        fields = {k.lower(): v for k, v in (line.split(": ", 1) for line in head[1:] if ": " in line)}
        self.error = None
        if self.status != 200:
            self.error = json.loads(self._exact(int(fields.get("content-length", "0"))))

    def _recv(self):
        chunk = self.sock.recv(65536)
        if not chunk:
            raise EOFError("the stream ended")
        self.buf += chunk

    def _until(self, separator):
        while separator not in self.buf:
            self._recv()
        at = self.buf.index(separator)
        out, self.buf = self.buf[:at], self.buf[at + len(separator):]
        return out

    def _exact(self, n):
        while len(self.buf) < n:
            self._recv()
        out, self.buf = self.buf[:n], self.buf[n:]
        return out

    def _body(self, n):
        while len(self.body) < n:
            size = int(self._until(b"\r\n"), 16)
            if size == 0:
                raise EOFError("the stream ended")
            self.body += self._exact(size)
            self._exact(2)
        out, self.body = self.body[:n], self.body[n:]
        return out

    def message(self):
        """The next message: (header, body)."""
        head, body = struct.unpack(">II", self._body(8))
        header = json.loads(self._body(head))
        return header, self._body(body)

    def ended(self):
        """Whether the server has closed the stream (a read gives no more bytes)."""
        try:
            while True:
                self._recv()
        except EOFError:
            return True
        except OSError:
            return True

    def close(self):
        self.sock.close()


def post_state(base, page, seq, params, timeout=60):
    """POST /state for `page`: (status, JSON answer)."""
    query = urllib.parse.urlencode([("page", page), ("seq", str(seq))] + list(params))
    request = urllib.request.Request(base + "/state?" + query, method="POST")
    try:
        with urllib.request.urlopen(request, timeout=timeout) as r:
            return r.status, json.loads(r.read())
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read())
