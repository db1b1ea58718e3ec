"""The operator gateway: REST API over the ground station's Zenoh RPC."""

from ground_station.gateway.app import create_app
from ground_station.gateway.gestures import Vocabulary
from ground_station.gateway.rpc import GsClient
from ground_station.gateway.settings import GatewaySettings

__all__ = ["GatewaySettings", "GsClient", "Vocabulary", "create_app"]
