"""Waiting for a worker's answer on the server's event loop, not on a thread.

A load step's request is written to the session's worker by the event loop that read the
step (:meth:`explorer.solving.workers.SolverProcesses.send_now`). Its answer used to be awaited
by a thread of a pool, blocked on the worker's pipe: when the answer came, the operating
system had to wake that thread, the thread had to get Python's lock from the busy event
loop, and then hand the result back to the loop: 3-5 ms a step on a loaded server (the
solve itself takes ~1 ms). Here the event loop watches the pipe itself
(``add_reader``) and reads the answer when it is there.

Only the plain case is taken here: the answer arrives within :data:`LOOP_WAIT_S`, whole.
A worker that ends, or an answer that takes longer, goes back to the thread's way
(:meth:`explorer.solving.workers.SolverProcesses.result`), which replaces the worker, runs the
request again or gives up after the time limit. So does an answer larger than
:data:`LOOP_READ_AT_MOST` (its size read from its prefix, not taken from the pipe): a
result of many output times (3.5 MB at 2000) is larger than the pipe holds, and reading
it on the loop waited for the worker to write the rest (on a saturated server the loop
stood in that read for over 0.5 s, three times in one load test:
benchmarks/results/load_test.md, run AH). A slider step's answer is ~0.2 MB (20 output
times) to 0.5 MB (200).

Nothing here imports Panel.
"""

from __future__ import annotations

import array
import asyncio
import os
import socket
import struct
from collections.abc import Callable

from .workers import SentRequest

#: The event loop waits this long for an answer [s] before a thread takes the wait over
#: (a slow solve, or a stuck worker: the thread applies the time limit).
LOOP_WAIT_S = 2.0
#: Answers up to this many bytes are read on the event loop, larger ones by a thread.
LOOP_READ_AT_MOST = 2**20


def when_answered(sent: SentRequest, on_answer: Callable[[], None],
                  on_other: Callable[[], None]) -> bool:
    """Call ``on_answer()`` on the running event loop once the answer to ``sent`` is in
    its worker's pipe (reading it then does not block), or ``on_other()`` if the worker
    ends first or no answer came within :data:`LOOP_WAIT_S`. Exactly one of them is
    called, once.

    Returns False (and calls neither) when the calling thread runs no event loop.
    """
    try:
        loop = asyncio.get_running_loop()
    except RuntimeError:
        return False
    lane = sent.lane
    connection, sentinel = lane.connection, lane.process.sentinel
    fds = (connection.fileno(), sentinel)
    done = False

    def finish() -> None:
        nonlocal done
        if done:
            return
        done = True
        timer.cancel()
        for fd in fds:
            loop.remove_reader(fd)
        try:
            # a pipe whose worker ended reads as ready too (its end): the thread's way
            # tells the two apart and replaces the worker. Just after the worker is killed
            # its pipe's end can be read before the process is seen to have ended (on a
            # loaded machine): an answer has bytes waiting, the end has none
            answered = (connection.poll(0) and lane.process.is_alive()
                        and _bytes_waiting(connection.fileno())
                        and _message_size(connection.fileno()) <= LOOP_READ_AT_MOST)
        except (OSError, EOFError, ValueError):  # the pipe closed (a shutdown)
            answered = False
        (on_answer if answered else on_other)()

    timer = loop.call_later(LOOP_WAIT_S, finish)
    try:
        for fd in fds:
            loop.add_reader(fd, finish)
    except (OSError, ValueError, NotImplementedError):  # a closed pipe; a loop without
        timer.cancel()                                   # readers
        for fd in fds:
            loop.remove_reader(fd)
        return False
    return True


def _bytes_waiting(fd: int) -> bool:
    """Whether bytes wait to be read on the pipe ``fd`` (True where that cannot be asked:
    then the process's state alone decides)."""
    try:
        import fcntl
        import termios
    except ImportError:  # not a POSIX system
        return True
    count = array.array("i", [0])
    try:
        fcntl.ioctl(fd, termios.FIONREAD, count, True)
    except OSError:
        return True
    return count[0] > 0


def _message_size(fd: int) -> int:
    """The size [bytes] of the message of ``multiprocessing.connection`` whose start
    waits on the socket pair ``fd``, read from its prefix without taking it
    (``MSG_PEEK``); 0 where it cannot be read so (a plain pipe, the prefix not all there
    yet)."""
    copy = os.dup(fd)  # (closing the copy leaves ``fd`` open)
    try:
        peer = socket.socket(fileno=copy)
    except OSError:  # not a socket
        os.close(copy)
        return 0
    try:
        head = peer.recv(12, socket.MSG_PEEK | socket.MSG_DONTWAIT)
    except OSError:
        return 0
    finally:
        peer.close()
    if len(head) < 4:
        return 0
    (size,) = struct.unpack("!i", head[:4])
    if size != -1:
        return size
    return struct.unpack("!Q", head[4:12])[0] if len(head) == 12 else 0
