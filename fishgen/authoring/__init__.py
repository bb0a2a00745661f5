"""Species-authoring tools: helpers for writing and preparing VRFish species files
(for example placing texture points the way the thesis' Fixel tool did). The build
pipeline does not use them."""
