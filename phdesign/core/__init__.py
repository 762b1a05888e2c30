"""The base of phdesign: errors, argument checks, budgets, defaults, text and files.

It imports nothing else of phdesign, so every layer may use it.
"""
