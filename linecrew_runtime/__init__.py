"""The runtime every linecrew process shares, one floor above the wire
contract (:mod:`proto`, the only package it imports): the Zenoh bus layer
and router, process plumbing (signals, health), structured logging, the
mission clock, settings, and the scenarios a site starts from."""
