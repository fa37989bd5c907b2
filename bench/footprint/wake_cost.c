// What one wake-up costs on this machine, whatever the program does in it: a child writes one byte into a
// pipe every GAP microseconds; the parent waits in epoll_wait, reads it and waits again. Prints the CPU
// time the parent's thread was charged per wake-up (/proc/thread-self/schedstat), the floor under
// airsegd's idle CPU for a given number of wake-ups a second.
//   cc -O2 -o /tmp/wake_cost bench/footprint/wake_cost.c && /tmp/wake_cost 100000 100
#define _GNU_SOURCE
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/epoll.h>
#include <sys/wait.h>
#include <unistd.h>

static long long thread_cpu_ns(void) {
    long long ns = 0;
    FILE* f = fopen("/proc/thread-self/schedstat", "r");
    if (f == NULL || fscanf(f, "%lld", &ns) != 1) {
        perror("wake_cost: /proc/thread-self/schedstat");
        exit(1);
    }
    fclose(f);
    return ns;
}

int main(int argc, char** argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: %s GAP_US COUNT\n", argv[0]);
        return 2;
    }
    const int gap_us = atoi(argv[1]);
    const int count = atoi(argv[2]);
    int p[2];
    if (pipe2(p, O_NONBLOCK) != 0) {
        perror("wake_cost: pipe2");
        return 1;
    }
    const pid_t child = fork();
    if (child == 0) {
        for (int i = 0; i < count; ++i) {
            usleep((useconds_t)gap_us);
            if (write(p[1], "x", 1) != 1) {
                _exit(1);
            }
        }
        _exit(write(p[1], "q", 1) == 1 ? 0 : 1);
    }
    const int ep = epoll_create1(0);
    struct epoll_event ev = {.events = EPOLLIN | EPOLLET};
    epoll_ctl(ep, EPOLL_CTL_ADD, p[0], &ev);
    const long long start = thread_cpu_ns();
    int wakes = 0;
    for (;;) {
        struct epoll_event out[4];
        if (epoll_wait(ep, out, 4, -1) <= 0) {
            continue;
        }
        ++wakes;
        char buf[64];
        const ssize_t n = read(p[0], buf, sizeof buf);
        if (n > 0 && buf[n - 1] == 'q') {
            break;
        }
    }
    const long long spent = thread_cpu_ns() - start;
    waitpid(child, NULL, 0);
    printf("%d wake-ups %d us apart: %.1f us of CPU each\n", wakes, gap_us, spent / 1000.0 / wakes);
    return 0;
}
