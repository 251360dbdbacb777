import weft, time, signal, os, threading, sys
law = [l for l in [getattr(weft,'Law',None)] if l]
print([n for n in dir(weft) if 'aw' in n.lower() or 'gamma' in n.lower()])
